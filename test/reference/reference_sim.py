#!/usr/bin/python3
"""Continuous-time reference simulation of the projection-based collision avoidance loop.

This is an independent implementation of the closed loop of Gehlot et al.,
"Projection-Based Inter-Agent Collision Avoidance in Dual Agent Systems", in the
form fixed by doc/math.md of the shared notes. It exists to cross-check the
sampled C++ simulator ``cf_sim``: it reads the same scenario YAML
(doc/cf_sim.md, section 'Scenario files'), integrates leader, follower and CF estimator together
as one ODE with ``scipy.integrate.solve_ivp`` (no sampling, no zero-order hold)
and prints the same summary line.

State and equations (all continuous in time)::

    xi     = x_1 - x_2 - d,   y = C xi,   y_hat = C xi_hat
    u_a    = G_e (y - y_hat) + S_21 y_hat         (tracker enabled, else 0)
    a_1    = u_1 + pinv(B) u_d(t)                 (leader_information.disturbance, else u_1)
    u_ff   = a_1                                  (leader_information.command, else 0)
    u_2    = G y + u_a + u_ff
    x_1'   = A x_1 + B u_1(t) + u_d(t)
    x_2'   = A x_2 + B u_2
    h      = A_c xi_hat - B u_a + L (y_hat - y)   [+ B (a_1 - u_ff) if
                                                   leader_information.estimator]
    xi_hat' = h - f Gamma^-1 grad_f (grad_f^T h) / (grad_f^T Gamma^-1 grad_f)
                                                  if f > 0 and grad_f^T h > 0
            = h                                   otherwise

with A_c = A - B G C, Gamma (A_c + L C) + (A_c + L C)^T Gamma = -Q and
f = ((1 + eps) ||xi_hat||^2 - xi_max^2) / (eps xi_max^2), xi_max = (1 - alpha) ||d||.

a_1 is the leader acceleration that the follower is told (leader_information):
with ``disturbance: true`` it includes the part of the leader's disturbance
that acts through B, pinv(B) u_d (for a double integrator the velocity-rate
half of u_d); the rest, (I - B pinv(B)) u_d (the position-rate half), reaches
the follower through xi only. The flag matters only when ``command`` or
``estimator`` is on. With both on, B (a_1 - u_ff) = 0: the estimator then
needs no model of the fed-forward acceleration, which cancels in xi'.

Turning slots (doc/math.md, section 'Turning slots', (T1)-(T3); ``formation.slots:
turning``, a double integrator of 2 or 3 axes). The slot d = [d_p; 0] is given in the
leader's body frame and turned about z by the slot heading theta, two more states
integrated with the rest::

    psi     = atan2(v_y, v_x)  of the leader's velocity v (its heading)
    psi'    = (v_x a_y - v_y a_x) / (v_x^2 + v_y^2),  a = u_1 + pinv(B) u_d (its true
              acceleration); psi := theta, psi' := 0 where ||v|| < min_speed
    theta'' = clamp(w^2 wrap(psi - theta) + 2 zeta w (psi' - theta'), +-beta),
              and theta'' <= 0 at theta' >= max_yaw_rate (>= 0 at <= -max_yaw_rate)   (T1)
    D       = [R(theta) d_p; theta' J R(theta) d_p]                                 (T2)
    xi      = x_1 - x_2 - D
    u_r     = -(theta'' J + theta'^2 J^2) R(theta) d_p                              (T3)
    u_2     = G y + u_a + u_ff + u_r

with wrap() to (-pi, pi], R(theta) the turn of the x-y part by theta (z kept) and
J = [[0, -1], [1, 0]] on x-y (0 on z). u_r is a known input that cancels between the
plant and the estimator's model (the augmentation that acts, u_2 - G y - u_ff - u_r, is
u_a), so h above is unchanged. theta(0) = psi(0) (0 if the leader starts below
min_speed), theta'(0) = 0, and the follower starts at x_2(0) = x_1(0) - D(theta(0), 0)
- xi_0 with xi_0 = x_1(0) - x_2(0) - d from the scenario: on its turned slot if the
scenario puts it on its slot. In 3-D the threshold is on the whole speed ||v||, as
doc/math.md writes it. Where cf_sim holds theta'' and u_r over a control period and
takes psi' as a difference quotient, this is exact in time: the two agree to O(T).

``formation.turning.reversing`` (cf_sim.md) is not in (T1): only ``false`` is accepted.

Formations: a ``formation`` section (keys as cf_sim's) is covered when every follower
looks at the leader, i.e. ``followers: 1`` (either topology) or ``topology: star``; a
chain of more followers is refused (exit 2). Follower i runs the pair's loop on its own
d_i (doc/formations.md: line i d; V ceil(i/2) R(+-half_angle) d, + for odd i), with its
own xi_max, and starts with the scenario's xi_0; the followers do not interact, so each
is simulated alone. The output is then cf_sim's: a line
``follower_<i> target=leader max_xi=..`` per follower, then
``formation followers=.. topology=.. shape=.. slots=.. min_pair_separation=.. wall_s=..``
(the smallest distance between any two agents, leader included, on the grid); --csv FILE
writes FILE with _follower_<i> before its extension, per follower.

The input and disturbance pulses make the right-hand side discontinuous in time,
so the integration is restarted at every pulse edge. Inside a segment the
right-hand side is Lipschitz (the projection term vanishes continuously at
f = 0 and at grad_f^T h = 0), except with turning slots. There theta'' switches where
theta' reaches +-max_yaw_rate, and the yaw rate then slides on that surface; the solver
would step to and fro across it (LSODA stalls), so the rate limit is a discrete mode and
the integration is also restarted where it switches (terminal events,
rate_limit_events()). Where ||v|| crosses min_speed and where psi - theta crosses
+-pi, theta'' jumps once, and the solver's error control crosses it (the summary of the
figure eight, with the rate limit active for 63 of its 120 s, moves by < 3e-7 m from
rtol 1e-6 to 1e-9).
The solution is reported on the grid
t_k = k / control_rate, k = 0 .. N with N = floor(duration * control_rate), the
rows of the CSV of cf_sim; with turning slots the CSV adds cf_sim's columns
slot_heading, slot_yaw_rate, slot_yaw_acceleration, slot_p_* (R(theta) d_p) and
u_slot_* (u_r).

Usage::

    reference_sim.py SCENARIO.yaml [--set key=value]... [--method LSODA]
                     [--rtol 1e-6] [--atol 1e-9] [--max-step S] [--csv FILE]

Exit codes: 0 success, 1 integration failure, 2 bad command line or scenario.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import sys
import time
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np
import yaml
from scipy.integrate import solve_ivp
from scipy.linalg import solve_continuous_lyapunov

PROG = "reference_sim"


class ScenarioError(Exception):
    """A scenario or override that does not follow doc/cf_sim.md, section 'Scenario files'."""


# --------------------------------------------------------------------------
# Scenario format: allowed keys
# --------------------------------------------------------------------------

# A dict maps allowed keys to the schema of their value; None is a leaf
# (its value is checked when the scenario is built); a one-element list
# [schema] is a YAML list whose items follow schema.
_PULSE = {"start": None, "end": None, "vector": None}
_SINUSOID = {"amplitude": None, "frequency": None, "phase": None}
_GAIN = {"gain": None, "natural_frequency": None, "damping": None}
SCHEMA = {
    "model": {
        "type": None,
        "dimension": None,
        "A": None,
        "B": None,
        "position_dimension": None,
        "C": None,
    },
    "controller": {
        "control_rate": None,
        "separation": None,
        "alpha": None,
        "epsilon": None,
        "baseline": dict(_GAIN),
        "estimator": {
            "gain": None,
            "lyapunov_weight": None,
            "substeps": None,
            "initial_estimate": None,
        },
        "tracker": {"enabled": None, "reference_gain": None, **_GAIN},
        "leader_information": {"command": None, "estimator": None, "disturbance": None},
    },
    "leader": {
        "initial_state": None,
        "input": {"pulses": [_PULSE], "sinusoids": [_SINUSOID]},
        "disturbance": [_PULSE],
    },
    "follower": {"initial_state": None},
    "simulation": {"duration": None},
    "formation": {
        "followers": None,
        "topology": None,
        "shape": None,
        "half_angle": None,
        "slots": None,
        "turning": {
            "natural_frequency": None,
            "damping": None,
            "max_yaw_rate": None,
            "max_yaw_acceleration": None,
            "min_speed": None,
            "reversing": None,
        },
    },
}


def check_keys(node, schema, path=""):
    """Raise ScenarioError naming the first key that the format does not define."""
    if schema is None:
        return
    if isinstance(schema, list):
        if node is None:
            return
        if not isinstance(node, list):
            raise ScenarioError(f"{path}: expected a list")
        for i, item in enumerate(node):
            check_keys(item, schema[0], f"{path}.{i}")
        return
    if node is None:
        return
    if not isinstance(node, dict):
        raise ScenarioError(f"{path or '<root>'}: expected a mapping")
    for key, value in node.items():
        sub = f"{path}.{key}" if path else str(key)
        if key not in schema:
            raise ScenarioError(f"unknown key '{sub}'")
        check_keys(value, schema[key], sub)


def apply_override(root, assignment):
    """Apply one ``--set a.b.c=VALUE`` override to the raw scenario tree.

    VALUE is parsed as YAML. A path element that is an integer indexes a list
    (index == len appends, for the last element only). Missing mappings on
    the path are created; whether the resulting key is allowed is checked
    afterwards by check_keys().
    """
    if "=" not in assignment:
        raise ScenarioError(f"--set '{assignment}': expected key=value")
    dotted, text = assignment.split("=", 1)
    parts = dotted.strip().split(".")
    if not dotted.strip() or any(not p for p in parts):
        raise ScenarioError(f"--set '{assignment}': empty key")
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ScenarioError(f"--set {dotted}: cannot parse value: {exc}") from None
    node = root
    for depth, part in enumerate(parts):
        last = depth == len(parts) - 1
        where = ".".join(parts[: depth + 1])
        if isinstance(node, list):
            try:
                index = int(part)
            except ValueError:
                raise ScenarioError(f"--set {dotted}: '{where}' must be a list index") from None
            if index == len(node) and last:
                node.append(value)
                return
            if not 0 <= index < len(node):
                raise ScenarioError(f"--set {dotted}: index {index} out of range at '{where}'")
            if last:
                node[index] = value
                return
            node = node[index]
        elif isinstance(node, dict):
            if last:
                node[part] = value
                return
            if node.get(part) is None:
                node[part] = {}
            node = node[part]
        else:
            parent = ".".join(parts[:depth])
            raise ScenarioError(f"--set {dotted}: '{parent}' is not a mapping or list")


# --------------------------------------------------------------------------
# Value parsing helpers
# --------------------------------------------------------------------------

def _is_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def get(node, key, path, default=None, required=True):
    """Return node[key]; raise naming path.key if it is required and missing."""
    if isinstance(node, dict) and node.get(key) is not None:
        return node[key]
    if required:
        raise ScenarioError(f"missing key '{path + '.' if path else ''}{key}'")
    return default


def as_float(v, path):
    if not _is_number(v):
        raise ScenarioError(f"{path}: expected a number, got {v!r}")
    x = float(v)
    if not math.isfinite(x):
        raise ScenarioError(f"{path}: not finite")
    return x


def as_bool(v, path):
    if not isinstance(v, bool):
        raise ScenarioError(f"{path}: expected true or false, got {v!r}")
    return v


def as_vector(v, path, size):
    if not isinstance(v, list) or not all(_is_number(x) for x in v):
        raise ScenarioError(f"{path}: expected a list of {size} numbers")
    if len(v) != size:
        raise ScenarioError(f"{path}: expected {size} entries, got {len(v)}")
    return np.array(v, dtype=float)


def as_matrix(v, path, rows, cols):
    """A list of rows, or a plain number s meaning s*I (square only; 0 is any shape)."""
    if _is_number(v):
        if rows != cols and float(v) != 0.0:
            raise ScenarioError(
                f"{path}: a plain number means s*I and needs a square matrix, "
                f"but the expected size is {rows} x {cols}")
        return float(v) * np.eye(rows, cols)
    if (not isinstance(v, list) or not v
            or not all(isinstance(r, list) and all(_is_number(x) for x in r) for r in v)):
        raise ScenarioError(f"{path}: expected a {rows} x {cols} matrix (a list of rows)")
    if len(v) != rows or any(len(r) != cols for r in v):
        shape = f"{len(v)} x {len(v[0])}" if len(set(map(len, v))) == 1 else "ragged"
        raise ScenarioError(f"{path}: expected a {rows} x {cols} matrix, got {shape}")
    return np.array(v, dtype=float)


def as_axis_values(v, path, k):
    """A number (same on every axis) or a list of k numbers."""
    if _is_number(v):
        return np.full(k, float(v))
    return as_vector(v, path, k)


def is_hurwitz(M):
    return M.size == 0 or bool(np.max(np.linalg.eigvals(M).real) < 0.0)


# --------------------------------------------------------------------------
# Scenario
# --------------------------------------------------------------------------

@dataclass
class Scenario:
    """A parsed scenario with the derived matrices of the controller."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    k: int                      # number of position entries at the head of x
    double_integrator: bool
    control_rate: float
    d: np.ndarray
    alpha: float
    epsilon: float
    G: np.ndarray
    L: np.ndarray
    Q: np.ndarray
    initial_estimate: str
    tracker: bool
    Ge: np.ndarray
    S21: np.ndarray
    info_command: bool
    info_estimator: bool
    info_disturbance: bool
    x1_0: np.ndarray
    x2_0: np.ndarray
    input_pulses: list = field(default_factory=list)   # (start, end, m-vector)
    sinusoids: list = field(default_factory=list)      # (amplitude, freq, phase)
    disturbances: list = field(default_factory=list)   # (start, end, n-vector)
    duration: float = 0.0
    formation: Formation = None     # None: the pair, no formation section

    def __post_init__(self):
        self.n, self.m = self.B.shape
        self.p = self.C.shape[0]
        self.Ac = self.A - self.B @ self.G @ self.C
        self.F = self.Ac + self.L @ self.C
        self.xi_max = (1.0 - self.alpha) * float(np.linalg.norm(self.d))
        self.xi_soft = self.xi_max / math.sqrt(1.0 + self.epsilon)
        self.perimeter = self.alpha * float(np.linalg.norm(self.d))
        self.Gamma = lyapunov_gamma(self.F, self.Q)
        self.Gamma_inv = np.linalg.inv(self.Gamma)
        self.B_pinv = np.linalg.pinv(self.B)
        self.turning = (self.formation.turning
                        if self.formation is not None and self.formation.slots == "turning"
                        else None)


def lyapunov_gamma(F, Q):
    """Gamma = Gamma^T > 0 with Gamma F + F^T Gamma = -Q.

    scipy's solve_continuous_lyapunov(a, q) solves a X + X a^H = q, so the
    equation above is a = F^T, q = -Q. The residual is checked explicitly.
    """
    Gamma = solve_continuous_lyapunov(F.T, -Q)
    Gamma = 0.5 * (Gamma + Gamma.T)
    residual = np.linalg.norm(Gamma @ F + F.T @ Gamma + Q) / max(1.0, np.linalg.norm(Q))
    if not residual < 1e-9:
        raise ScenarioError(f"Lyapunov equation for Gamma not solved (residual {residual:.3g})")
    if np.min(np.linalg.eigvalsh(Gamma)) <= 0.0:
        raise ScenarioError("Gamma is not positive definite")
    return Gamma


def _gain(node, path, m, p, k, double_integrator, c_is_identity):
    """A gain matrix given as `gain` or as natural_frequency/damping per axis."""
    has_matrix = node.get("gain") is not None
    has_modal = node.get("natural_frequency") is not None or node.get("damping") is not None
    if has_matrix and has_modal:
        raise ScenarioError(f"{path}: 'gain' and 'natural_frequency'/'damping' exclude each other")
    if has_matrix:
        return as_matrix(node["gain"], f"{path}.gain", m, p)
    if not has_modal:
        raise ScenarioError(f"missing key '{path}.gain' (or natural_frequency and damping)")
    if not (double_integrator and c_is_identity):
        raise ScenarioError(
            f"{path}: natural_frequency/damping need model double_integrator with C = I")
    wn = as_axis_values(get(node, "natural_frequency", path), f"{path}.natural_frequency", k)
    zeta = as_axis_values(get(node, "damping", path), f"{path}.damping", k)
    G = np.zeros((k, 2 * k))
    for i in range(k):
        G[i, i] = wn[i] ** 2
        G[i, k + i] = 2.0 * zeta[i] * wn[i]
    return G


def _pulses(items, path, size):
    if items is None:
        return []
    if not isinstance(items, list):
        raise ScenarioError(f"{path}: expected a list of pulses")
    out = []
    for i, item in enumerate(items):
        ipath = f"{path}.{i}"
        if not isinstance(item, dict):
            raise ScenarioError(f"{ipath}: expected a mapping with start, end, vector")
        start = as_float(get(item, "start", ipath), f"{ipath}.start")
        end = as_float(get(item, "end", ipath), f"{ipath}.end")
        if not end > start:
            raise ScenarioError(f"{ipath}: end must be greater than start")
        out.append((start, end, as_vector(get(item, "vector", ipath), f"{ipath}.vector", size)))
    return out


@dataclass(frozen=True)
class Turning:
    """The slot heading generator (T1) of doc/math.md, section 'Turning slots'."""

    natural_frequency: float = 1.0      # omega_theta, rad/s
    damping: float = 1.0                # zeta_theta
    max_yaw_rate: float = 0.5           # omega_max, rad/s
    max_yaw_acceleration: float = 0.5   # beta, rad/s^2
    min_speed: float = 0.5              # m/s: below it the target has no heading


@dataclass(frozen=True)
class Formation:
    """The scenario's formation section: followers that all look at the leader."""

    followers: int = 1
    topology: str = "star"
    shape: str = "line"
    half_angle: float = math.pi / 6.0   # rad, each arm of a V to d
    slots: str = "world"                # world | turning
    turning: Turning = field(default_factory=Turning)


def parse_formation(node, double_integrator, k):
    """The formation section, or None without one.

    Covered: a star (every follower looks at the leader, so that each runs the
    pair's loop on its own d_i and is simulated alone) and the single follower of
    either topology. A chain of more than one follower is refused.
    """
    if node is None:
        return None
    followers = get(node, "followers", "formation")
    if isinstance(followers, bool) or not isinstance(followers, int):
        raise ScenarioError(f"formation.followers: expected an integer, got {followers!r}")
    if not 1 <= followers <= 1000:
        raise ScenarioError(f"formation.followers: expected 1 .. 1000, got {followers}")
    topology = node.get("topology", "star")
    if topology not in ("star", "chain"):
        raise ScenarioError(f"formation.topology: expected star or chain, got {topology!r}")
    if topology == "chain" and followers > 1:
        raise ScenarioError(
            f"formation.topology = chain with {followers} followers: not covered by the "
            "reference, which simulates followers that look at the leader (a star, or "
            "followers: 1)")
    shape = node.get("shape", "line")
    if shape not in ("line", "v"):
        raise ScenarioError(f"formation.shape: expected line or v, got {shape!r}")
    half_angle = as_float(node.get("half_angle", Formation.half_angle), "formation.half_angle")
    if not 0.0 < half_angle < math.pi / 2.0:
        raise ScenarioError("formation.half_angle: must be in (0, pi/2)")
    slots = node.get("slots", "world")
    if slots not in ("world", "turning"):
        raise ScenarioError(f"formation.slots: expected world or turning, got {slots!r}")
    planar = double_integrator and k in (2, 3)
    if shape == "v" and not planar:
        raise ScenarioError("formation.shape = v needs a double_integrator model of 2 or 3 axes")
    if slots == "turning" and not planar:
        raise ScenarioError(
            "formation.slots = turning needs a double_integrator model of 2 or 3 axes "
            "(the slot turns about z); use world")

    tnode = node.get("turning") or {}
    if not isinstance(tnode, dict):
        raise ScenarioError("formation.turning: expected a mapping")
    # reversing (cf_sim.md) has no equation in doc/math.md's (T1): only its default is covered.
    if as_bool(tnode.get("reversing", False), "formation.turning.reversing"):
        raise ScenarioError(
            "formation.turning.reversing = true: not covered by the reference, which "
            "implements (T1) of doc/math.md (a reversing target swings the slot round)")
    values = {}
    for key, default in vars(Turning()).items():
        value = as_float(tnode.get(key, default), f"formation.turning.{key}")
        if key == "min_speed" and not value >= 0.0:
            raise ScenarioError("formation.turning.min_speed: must be >= 0")
        if key != "min_speed" and not value > 0.0:
            raise ScenarioError(f"formation.turning.{key}: must be > 0")
        values[key] = value
    return Formation(followers=followers, topology=topology, shape=shape,
                     half_angle=half_angle, slots=slots, turning=Turning(**values))


def slot_layout(formation, d, k):
    """d_i of followers 1 .. N (doc/formations.md): line i d; V ceil(i/2) R(+-half_angle) d.

    R turns the x-y part of d's position part, + for odd i and - for even i.
    """
    if formation is None:
        return [d]
    out = []
    for i in range(1, formation.followers + 1):
        if formation.shape == "line":
            out.append(i * d)
            continue
        angle = formation.half_angle if i % 2 else -formation.half_angle
        di = d.copy()
        di[:k] = rotate_z(d[:k], angle)
        out.append(math.ceil(i / 2) * di)
    return out


def rotate_z(p, angle):
    """R(angle) p: the x-y part (first two entries) turned by angle, the rest kept."""
    c, s = math.cos(angle), math.sin(angle)
    out = np.array(p, dtype=float)
    out[0] = c * p[0] - s * p[1]
    out[1] = s * p[0] + c * p[1]
    return out


def build_scenario(raw):
    """Validate the raw YAML tree and return a Scenario."""
    if not isinstance(raw, dict):
        raise ScenarioError("the scenario must be a YAML mapping")
    check_keys(raw, SCHEMA)

    model = get(raw, "model", "")
    mtype = get(model, "type", "model")
    if mtype == "double_integrator":
        for key in ("A", "B", "position_dimension"):
            if key in model:
                raise ScenarioError(f"model.{key} is only valid for model type linear")
        dim = get(model, "dimension", "model")
        if isinstance(dim, bool) or not isinstance(dim, int) or dim not in (1, 2, 3):
            raise ScenarioError("model.dimension: expected 1, 2 or 3")
        k = dim
        A = np.zeros((2 * k, 2 * k))
        A[:k, k:] = np.eye(k)
        B = np.vstack([np.zeros((k, k)), np.eye(k)])
        double_integrator = True
    elif mtype == "linear":
        if "dimension" in model:
            raise ScenarioError("model.dimension is only valid for model type double_integrator")
        A_raw = get(model, "A", "model")
        if not isinstance(A_raw, list):
            raise ScenarioError("model.A: expected an n x n matrix (a list of rows)")
        n = len(A_raw)
        A = as_matrix(A_raw, "model.A", n, n)
        B_raw = get(model, "B", "model")
        if not isinstance(B_raw, list) or not B_raw or not isinstance(B_raw[0], list):
            raise ScenarioError("model.B: expected an n x m matrix (a list of rows)")
        B = as_matrix(B_raw, "model.B", n, len(B_raw[0]))
        k = get(model, "position_dimension", "model")
        if isinstance(k, bool) or not isinstance(k, int) or not 1 <= k <= n:
            raise ScenarioError(f"model.position_dimension: expected an integer in 1..{n}")
        double_integrator = False
    else:
        raise ScenarioError(f"model.type: expected double_integrator or linear, got {mtype!r}")
    n, m = B.shape

    C_raw = model.get("C")
    if C_raw is None:
        C = np.eye(n)
    elif _is_number(C_raw):
        C = as_matrix(C_raw, "model.C", n, n)
    else:
        if not isinstance(C_raw, list):
            raise ScenarioError("model.C: expected a p x n matrix (a list of rows)")
        C = as_matrix(C_raw, "model.C", len(C_raw), n)
    p = C.shape[0]
    c_is_identity = C.shape == (n, n) and np.array_equal(C, np.eye(n))

    ctl = get(raw, "controller", "")
    control_rate = as_float(get(ctl, "control_rate", "controller"), "controller.control_rate")
    if not control_rate > 0:
        raise ScenarioError("controller.control_rate: must be > 0")
    d = as_vector(get(ctl, "separation", "controller"), "controller.separation", n)
    if np.linalg.norm(A @ d) > 1e-9 * max(1.0, np.linalg.norm(A) * np.linalg.norm(d)):
        raise ScenarioError("controller.separation: d must lie in ker(A)")
    if not np.linalg.norm(d) > 0:
        raise ScenarioError("controller.separation: must be non-zero")
    alpha = as_float(get(ctl, "alpha", "controller"), "controller.alpha")
    if not 0.0 <= alpha < 1.0:
        raise ScenarioError("controller.alpha: must be in [0, 1)")
    epsilon = as_float(get(ctl, "epsilon", "controller"), "controller.epsilon")
    if not epsilon > 0.0:
        raise ScenarioError("controller.epsilon: must be > 0")

    G = _gain(get(ctl, "baseline", "controller"), "controller.baseline",
              m, p, k, double_integrator, c_is_identity)
    if not is_hurwitz(A - B @ G @ C):
        raise ScenarioError("controller.baseline: A_c = A - B G C is not Hurwitz")

    est = get(ctl, "estimator", "controller")
    L = as_matrix(get(est, "gain", "controller.estimator"), "controller.estimator.gain", n, p)
    Q = as_matrix(get(est, "lyapunov_weight", "controller.estimator"),
                  "controller.estimator.lyapunov_weight", n, n)
    if not np.allclose(Q, Q.T, rtol=0, atol=1e-12) or np.min(np.linalg.eigvalsh(Q)) <= 0:
        raise ScenarioError(
            "controller.estimator.lyapunov_weight: Q must be symmetric positive definite")
    substeps = est.get("substeps")  # meaningful for the sampled simulator only
    if substeps is not None and (isinstance(substeps, bool) or not isinstance(substeps, int)
                                 or substeps < 1):
        raise ScenarioError("controller.estimator.substeps: expected an integer >= 1")
    init = est.get("initial_estimate", "measurement")
    if init not in ("measurement", "zero"):
        raise ScenarioError("controller.estimator.initial_estimate: expected measurement or zero")
    if not is_hurwitz(A - B @ G @ C + L @ C):
        raise ScenarioError("controller.estimator.gain: A_c + L C is not Hurwitz")

    trk = get(ctl, "tracker", "controller")
    tracker = as_bool(get(trk, "enabled", "controller.tracker"), "controller.tracker.enabled")
    Ge = _gain(trk, "controller.tracker", m, p, k, double_integrator, c_is_identity)
    S21 = as_matrix(trk.get("reference_gain", 0), "controller.tracker.reference_gain", m, p)
    if tracker and not is_hurwitz(A - B @ G @ C - B @ Ge @ C):
        raise ScenarioError("controller.tracker.gain: A_c - B G_e C is not Hurwitz")

    info = ctl.get("leader_information") or {}
    info_command = as_bool(info.get("command", False), "controller.leader_information.command")
    info_estimator = as_bool(info.get("estimator", False),
                             "controller.leader_information.estimator")
    info_disturbance = as_bool(info.get("disturbance", False),
                               "controller.leader_information.disturbance")

    leader = get(raw, "leader", "")
    x1_0 = as_vector(get(leader, "initial_state", "leader"), "leader.initial_state", n)
    inp = leader.get("input") or {}
    input_pulses = _pulses(inp.get("pulses"), "leader.input.pulses", m)
    sinusoids = []
    sins = inp.get("sinusoids")
    if sins is not None and not isinstance(sins, list):
        raise ScenarioError("leader.input.sinusoids: expected a list")
    for i, s in enumerate(sins or []):
        spath = f"leader.input.sinusoids.{i}"
        if not isinstance(s, dict):
            raise ScenarioError(f"{spath}: expected a mapping with amplitude, frequency, phase")
        amp = as_vector(get(s, "amplitude", spath), f"{spath}.amplitude", m)
        freq = as_float(get(s, "frequency", spath), f"{spath}.frequency")
        phase = as_float(s.get("phase", 0.0), f"{spath}.phase")
        sinusoids.append((amp, freq, phase))
    disturbances = _pulses(leader.get("disturbance"), "leader.disturbance", n)

    follower = get(raw, "follower", "")
    x2_0 = as_vector(get(follower, "initial_state", "follower"), "follower.initial_state", n)

    sim = get(raw, "simulation", "")
    duration = as_float(get(sim, "duration", "simulation"), "simulation.duration")
    if not duration > 0:
        raise ScenarioError("simulation.duration: must be > 0")

    formation = parse_formation(raw.get("formation"), double_integrator, k)

    return Scenario(A=A, B=B, C=C, k=k, double_integrator=double_integrator,
                    control_rate=control_rate, d=d, alpha=alpha, epsilon=epsilon,
                    G=G, L=L, Q=Q, initial_estimate=init, tracker=tracker, Ge=Ge, S21=S21,
                    info_command=info_command, info_estimator=info_estimator,
                    info_disturbance=info_disturbance,
                    x1_0=x1_0, x2_0=x2_0, input_pulses=input_pulses, sinusoids=sinusoids,
                    disturbances=disturbances, duration=duration, formation=formation)


def load_scenario(path, overrides=()):
    """Read a scenario file, apply the --set overrides, validate it."""
    try:
        with open(path, encoding="utf-8") as fh:
            raw = yaml.safe_load(fh)
    except OSError as exc:
        raise ScenarioError(f"cannot read {path}: {exc.strerror}") from None
    except yaml.YAMLError as exc:
        raise ScenarioError(f"{path}: invalid YAML: {exc}") from None
    if raw is None:
        raw = {}
    for assignment in overrides:
        if not isinstance(raw, dict):
            break
        apply_override(raw, assignment)
    return build_scenario(raw)


# --------------------------------------------------------------------------
# Closed loop
# --------------------------------------------------------------------------

def pulse_sum(pulses, t, size):
    """Sum of the pulse vectors active at times t (start <= t < end); t: (K,) -> (size, K)."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.zeros((size, t.size))
    for start, end, vec in pulses:
        on = (t >= start) & (t < end)
        out += np.outer(vec, on)
    return out


def sinusoid_sum(sinusoids, t, size):
    """Sum of amplitude * sin(2 pi f t + phase); t: (K,) -> (size, K)."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.zeros((size, t.size))
    for amp, freq, phase in sinusoids:
        out += np.outer(amp, np.sin(2.0 * math.pi * freq * t + phase))
    return out


def wrap_angle(x):
    """x wrapped to (-pi, pi]."""
    return x - 2.0 * math.pi * np.ceil((x - math.pi) / (2.0 * math.pi))


def target_heading(sc, x1, a1):
    """The leader's heading psi, its exact rate psi' and where it is defined; (K,) arrays each.

    psi = atan2(v_y, v_x) of the leader's velocity and psi' = (v_x a_y - v_y a_x) /
    (v_x^2 + v_y^2) its time derivative, a1 the leader's true acceleration (m = k entries).
    Defined where the horizontal speed ||(v_x, v_y)|| >= min_speed (doc/math.md, (T1)) and is
    not zero.
    """
    k = sc.k
    vx, vy = x1[k], x1[k + 1]
    vxy2 = vx * vx + vy * vy
    speed = np.sqrt(vxy2)
    defined = (speed >= sc.turning.min_speed) & (vxy2 > 0.0)
    psi = np.arctan2(vy, vx)
    psi_dot = (vx * a1[1] - vy * a1[0]) / np.where(vxy2 > 0.0, vxy2, 1.0)
    return psi, psi_dot, defined


def slot_heading_drive(tg, theta, theta_dot, psi, psi_dot, defined):
    """theta'' of (T1) before the rate limit: clamp(w^2 wrap(psi - theta) + 2 zeta w (psi' -
    theta'), +-beta), with psi := theta and psi' := 0 where psi is undefined (the slot stops
    turning and holds)."""
    psi = np.where(defined, psi, theta)
    psi_dot = np.where(defined, psi_dot, 0.0)
    w, zeta = tg.natural_frequency, tg.damping
    acc = w * w * wrap_angle(psi - theta) + 2.0 * zeta * w * (psi_dot - theta_dot)
    return np.clip(acc, -tg.max_yaw_acceleration, tg.max_yaw_acceleration)


def rate_limit_mode(tg, theta_dot):
    """+1 where theta' >= max_yaw_rate, -1 where theta' <= -max_yaw_rate, else 0."""
    return np.where(theta_dot >= tg.max_yaw_rate, 1,
                    np.where(theta_dot <= -tg.max_yaw_rate, -1, 0))


def slot_heading_acceleration(drive, rate_mode):
    """theta'' of (T1): the drive, with no further acceleration beyond the rate limit.

    rate_mode +1 (theta' at +max_yaw_rate) allows theta'' <= 0 only, -1 theta'' >= 0 only,
    0 (|theta'| below the limit) the drive as it is.
    """
    acc = np.where(rate_mode > 0, np.minimum(drive, 0.0), drive)
    return np.where(rate_mode < 0, np.maximum(acc, 0.0), acc)


def turned_slot(sc, theta, theta_dot, theta_ddot):
    """R(theta) d_p, the turned slot D of (T2) and u_r of (T3); (K,) arrays in.

    R turns the x-y part of d_p by theta about z; J = [[0, -1], [1, 0]] on x-y, 0 on z:
    D = [R d_p; theta' J R d_p], u_r = -(theta'' J + theta'^2 J^2) R d_p.
    Returns (k, K), (n, K), (m, K) arrays.
    """
    k = sc.k
    dp = sc.d[:k]
    c, s = np.cos(theta), np.sin(theta)
    r = np.tile(dp[:, None], (1, theta.size))                 # z part kept
    r[0] = c * dp[0] - s * dp[1]
    r[1] = s * dp[0] + c * dp[1]
    jr = np.zeros_like(r)                                     # J R d_p
    jr[0], jr[1] = -r[1], r[0]
    jjr = np.zeros_like(r)                                    # J^2 R d_p
    jjr[:2] = -r[:2]
    D = np.vstack([r, theta_dot * jr])
    ur = -(theta_ddot * jr + theta_dot * theta_dot * jjr)
    return r, D, ur


def closed_loop(sc, Z, u1, ud, rate_mode=None):
    """Every signal of the loop for K states at once.

    Z is (3n, K) with rows [x_1; x_2; xi_hat], or (3n + 2, K) with rows [x_1; x_2; xi_hat;
    theta; theta'] with turning slots; u1 is (m, K), ud is (n, K). rate_mode (turning slots)
    is the rate limit's mode (slot_heading_acceleration()), a number or (K,); None: read
    off theta' (rate_limit_mode()).
    Returns a namespace with the signals as (., K) arrays and zdot = dZ/dt.
    """
    n = sc.n
    K = Z.shape[1]
    x1, x2, xh = Z[:n], Z[n:2 * n], Z[2 * n:3 * n]
    if sc.turning is not None:
        theta, theta_dot = Z[3 * n], Z[3 * n + 1]
        a_true = u1 + sc.B_pinv @ ud                   # the leader's true acceleration
        psi, psi_dot, defined = target_heading(sc, x1, a_true)
        drive = slot_heading_drive(sc.turning, theta, theta_dot, psi, psi_dot, defined)
        if rate_mode is None:
            rate_mode = rate_limit_mode(sc.turning, theta_dot)
        theta_ddot = slot_heading_acceleration(drive, rate_mode)
        slot_p, D, ur = turned_slot(sc, theta, theta_dot, theta_ddot)
    else:
        D = sc.d[:, None]
        ur = np.zeros((sc.m, K))
    xi = x1 - x2 - D
    y = sc.C @ xi
    yh = sc.C @ xh
    if sc.tracker:
        ua = sc.Ge @ (y - yh) + sc.S21 @ yh
    else:
        ua = np.zeros((sc.m, K))
    a1 = u1 + sc.B_pinv @ ud if sc.info_disturbance else u1   # leader acceleration told
    uff = a1 if sc.info_command else np.zeros_like(u1)
    ub = sc.G @ y
    u2 = ub + ua + uff + ur

    # u_r is a known input, cancelled between plant and model: the estimator's
    # augmentation is u_2 - G y - u_ff - u_r = u_a, so h is the pair's.
    h = sc.Ac @ xh - sc.B @ ua + sc.L @ (yh - y)
    if sc.info_estimator:
        h = h + sc.B @ (a1 - uff)

    xm2 = sc.xi_max ** 2
    f = ((1.0 + sc.epsilon) * np.sum(xh * xh, axis=0) - xm2) / (sc.epsilon * xm2)
    grad = (2.0 * (1.0 + sc.epsilon) / (sc.epsilon * xm2)) * xh
    grad_h = np.sum(grad * h, axis=0)
    active = (f > 0.0) & (grad_h > 0.0)
    gi_grad = sc.Gamma_inv @ grad
    denom = np.sum(grad * gi_grad, axis=0)          # > 0 wherever f > 0
    scale = np.where(active, f * grad_h / np.where(active, denom, 1.0), 0.0)
    xh_dot = h - gi_grad * scale

    x1_dot = sc.A @ x1 + sc.B @ u1 + ud
    x2_dot = sc.A @ x2 + sc.B @ u2
    out = SimpleNamespace(xi=xi, xi_hat=xh, x1=x1, x2=x2, u=u2, u_baseline=ub,
                          u_tracker=ua, f=f, active=active,
                          zdot=np.vstack([x1_dot, x2_dot, xh_dot]))
    if sc.turning is not None:
        out.theta, out.theta_dot, out.theta_ddot = theta, theta_dot, theta_ddot
        out.theta_drive = drive
        out.slot_p, out.u_slot = slot_p, ur
        out.zdot = np.vstack([out.zdot, theta_dot, theta_ddot])
    return out


def initial_estimate(sc, xi0):
    if sc.initial_estimate == "zero":
        return np.zeros(sc.n)
    est = np.linalg.pinv(sc.C) @ (sc.C @ xi0)
    norm = np.linalg.norm(est)
    if norm > sc.xi_max:
        est *= sc.xi_max / norm
    return est


def initial_state(sc):
    """z(0) = [x_1(0); x_2(0); xi_hat(0)], with turning slots also theta(0), theta'(0) = 0.

    xi_0 = x_1(0) - x_2(0) - d from the scenario. With turning slots theta(0) = psi(0)
    (0 if the leader starts below min_speed) and the follower starts at
    x_1(0) - D(theta(0), 0) - xi_0: a follower on its world slot starts on its turned slot.
    """
    xi0 = sc.x1_0 - sc.x2_0 - sc.d
    z = [sc.x1_0, sc.x2_0, initial_estimate(sc, xi0)]
    if sc.turning is not None:
        x1 = sc.x1_0[:, None]
        psi, _, defined = target_heading(sc, x1, np.zeros((sc.m, 1)))
        theta0 = float(psi[0]) if defined[0] else 0.0
        _, D0, _ = turned_slot(sc, np.array([theta0]), np.zeros(1), np.zeros(1))
        z[1] = sc.x1_0 - D0[:, 0] - xi0
        z.append(np.array([theta0, 0.0]))
    return np.concatenate(z)


def time_grid(sc):
    """t_k = k / control_rate, k = 0 .. N, N = floor(duration * control_rate).

    One sample per control tick, the final state at t_N = duration included
    (as cf_sim writes its CSV).
    """
    periods = int(math.floor(sc.duration * sc.control_rate + 1e-9))
    return np.arange(periods + 1, dtype=float) / sc.control_rate


def segment_edges(sc):
    """0, duration and every pulse edge strictly between them, sorted."""
    edges = {0.0, sc.duration}
    for start, end, _ in sc.input_pulses + sc.disturbances:
        edges.update(e for e in (start, end) if 0.0 < e < sc.duration)
    return sorted(edges)


def rate_limit_events(sc, mode, u1_at, ud):
    """Terminal events that end a piece of constant rate-limit mode (turning slots).

    theta'' switches where theta' reaches +-max_yaw_rate and the drive still pushes on:
    integrated as it is, the solver would step to and fro across that surface (the
    slot's yaw rate slides on it). So the mode is a discrete state: in mode 0 the drive
    acts unlimited and the pieces end where theta' reaches +-max_yaw_rate; in mode +-1
    theta' stays at +-max_yaw_rate (theta'' = 0) until the drive turns back. Each piece's
    right-hand side is then Lipschitz in the state (but for psi's switches, which the
    solver's error control crosses).
    """
    rate = 3 * sc.n + 1
    wmax = sc.turning.max_yaw_rate

    def drive(t, z):
        return closed_loop(sc, z[:, None], u1_at(t), ud, mode).theta_drive[0]

    def event(fn, direction):
        fn.terminal, fn.direction = True, direction
        return fn

    if mode == 0:
        return [event(lambda t, z: z[rate] - wmax, 1.0), event(lambda t, z: z[rate] + wmax, -1.0)]
    return [event(drive, -float(mode))]


def simulate(sc, method="LSODA", rtol=1e-6, atol=1e-9, max_step=math.inf):
    """Integrate the closed loop; return (grid, Z on the grid, rate_mode on the grid,
    wall seconds, nfev).

    Z is (3n, K), or (3n + 2, K) with turning slots (rows as in closed_loop()); rate_mode
    (K,) is the rate limit's mode at each sample (0 without turning slots).
    """
    grid = time_grid(sc)
    z = initial_state(sc)
    Z = np.empty((z.size, grid.size))
    modes = np.zeros(grid.size, dtype=int)
    turning = sc.turning is not None
    rate = 3 * sc.n + 1
    mode = 0                                  # theta'(0) = 0: below the rate limit
    edges = segment_edges(sc)
    nfev = 0
    wall0 = time.perf_counter()
    for a, b in zip(edges[:-1], edges[1:]):
        mid = 0.5 * (a + b)
        u1_pulse = pulse_sum(sc.input_pulses, mid, sc.m)          # constant on [a, b)
        ud = pulse_sum(sc.disturbances, mid, sc.n)
        sins = sc.sinusoids

        def u1_at(t, u1_pulse=u1_pulse):
            return u1_pulse + sinusoid_sum(sins, t, sc.m) if sins else u1_pulse

        # Samples in [a, b); the last segment also takes a sample at b = duration.
        # The state is continuous, so an edge sample may come from either side.
        in_segment = (grid >= a) & ((grid < b) | (b == edges[-1]))
        idx = np.nonzero(in_segment)[0]
        t0, done, stalled = a, 0, 0
        while True:                           # pieces of constant rate-limit mode
            def rhs(t, zz, mode=mode, ud=ud):
                return closed_loop(sc, zz[:, None], u1_at(t), ud, mode).zdot[:, 0]

            t_eval = grid[idx[done:]]
            if t_eval.size == 0 or t_eval[-1] < b:
                t_eval = np.append(t_eval, b)          # also ask for the end state
            events = rate_limit_events(sc, mode, u1_at, ud) if turning else None
            sol = solve_ivp(rhs, (t0, b), z, method=method, t_eval=t_eval, events=events,
                            rtol=rtol, atol=atol, max_step=max_step)
            if not sol.success:
                raise RuntimeError(f"integration failed on [{t0:g}, {b:g}] s: {sol.message}")
            nfev += sol.nfev
            got = min(sol.t.size, idx.size - done)
            Z[:, idx[done:done + got]] = sol.y[:, :got]
            modes[idx[done:done + got]] = mode
            done += got
            if sol.status != 1:               # reached b
                z = sol.y[:, -1]
                break
            # A rate-limit event ended the piece: switch the mode and go on from there.
            fired = next(i for i, te in enumerate(sol.t_events) if te.size)
            t_event, z = sol.t_events[fired][0], sol.y_events[fired][0].copy()
            stalled = stalled + 1 if t_event - t0 <= 1e-12 * max(1.0, abs(t0)) else 0
            if stalled > 100:
                raise RuntimeError(f"the slot's rate limit switches without end at {t0:g} s")
            t0 = t_event
            if mode == 0:                     # theta' reached +-max_yaw_rate
                z[rate] = math.copysign(sc.turning.max_yaw_rate, z[rate])
                u1 = u1_at(t0)
                drive = closed_loop(sc, z[:, None], u1, ud, 0).theta_drive[0]
                mode = int(np.sign(z[rate])) if drive * z[rate] > 0.0 else 0
            else:                             # the drive turned back
                mode = 0
    wall = time.perf_counter() - wall0
    return grid, Z, modes, wall, nfev


def signals_on_grid(sc, grid, Z, rate_mode=None):
    """All CSV signals on the grid as a dict of column name -> 1-D array (in CSV order)."""
    u1 = pulse_sum(sc.input_pulses, grid, sc.m) + sinusoid_sum(sc.sinusoids, grid, sc.m)
    ud = pulse_sum(sc.disturbances, grid, sc.n)
    s = closed_loop(sc, Z, u1, ud, rate_mode)
    n, k = sc.n, sc.k
    K = grid.size
    cols = {"t": grid}
    for i in range(n):
        cols[f"xi_{i}"] = s.xi[i]
    for i in range(n):
        cols[f"xi_hat_{i}"] = s.xi_hat[i]
    cols["norm_xi"] = np.linalg.norm(s.xi, axis=0)
    cols["norm_xi_hat"] = np.linalg.norm(s.xi_hat, axis=0)
    cols["xi_max"] = np.full(K, sc.xi_max)
    cols["xi_soft"] = np.full(K, sc.xi_soft)
    cols["f"] = s.f
    cols["projection_active"] = s.active.astype(float)
    for i in range(k):
        cols[f"leader_p_{i}"] = s.x1[i]
    for i in range(k):
        cols[f"follower_p_{i}"] = s.x2[i]
    if sc.double_integrator:
        for i in range(k):
            cols[f"leader_v_{i}"] = s.x1[k + i]
        for i in range(k):
            cols[f"follower_v_{i}"] = s.x2[k + i]
    cols["separation"] = np.linalg.norm(s.x1[:k] - s.x2[:k], axis=0)
    cols["perimeter"] = np.full(K, sc.perimeter)
    for name, arr in (("u", s.u), ("u_baseline", s.u_baseline), ("u_tracker", s.u_tracker),
                      ("leader_u", u1)):
        for i in range(sc.m):
            cols[f"{name}_{i}"] = arr[i]
    for i in range(n):
        cols[f"ud_{i}"] = ud[i]
    if sc.turning is not None:
        cols["slot_heading"] = s.theta
        cols["slot_yaw_rate"] = s.theta_dot
        cols["slot_yaw_acceleration"] = s.theta_ddot
        for i in range(k):
            cols[f"slot_p_{i}"] = s.slot_p[i]
        for i in range(sc.m):
            cols[f"u_slot_{i}"] = s.u_slot[i]
    return cols


def write_csv(path, cols):
    names = list(cols)
    data = np.column_stack([cols[c] for c in names])
    np.savetxt(path, data, fmt="%.17g", delimiter=",", header=",".join(names), comments="")


def summary(sc, cols, wall):
    norm_xi = cols["norm_xi"]
    return {
        "max_xi": float(np.max(norm_xi)),
        "max_xi_hat": float(np.max(cols["norm_xi_hat"])),
        "xi_max": sc.xi_max,
        "min_separation": float(np.min(cols["separation"])),
        "time_outside": int(np.count_nonzero(norm_xi > sc.xi_max)) / sc.control_rate,
        "wall_s": wall,
    }


# --------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------

def parse_args(argv):
    ap = argparse.ArgumentParser(
        prog="reference_sim.py",
        description="Continuous-time reference simulation of a scenario (see module docstring).")
    ap.add_argument("scenario", help="scenario YAML (doc/cf_sim.md, section 'Scenario files')")
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                    help="override a scenario entry by dotted path; VALUE is YAML "
                         "(a numeric path element indexes a list); repeatable")
    ap.add_argument("--method", default="LSODA", help="solve_ivp method (default LSODA)")
    ap.add_argument("--rtol", type=float, default=1e-6, help="relative tolerance (default 1e-6)")
    ap.add_argument("--atol", type=float, default=1e-9, help="absolute tolerance (default 1e-9)")
    ap.add_argument("--max-step", type=float, default=math.inf,
                    help="largest step, s (default: no limit)")
    ap.add_argument("--csv", metavar="FILE", help="write the sampled signals to FILE")
    return ap.parse_args(argv)


def follower_scenarios(sc):
    """(name, scenario) per follower; name None for the pair without a formation section.

    Every follower looks at the leader (a star, or a single follower), so each runs
    the pair's loop on its own d_i and is simulated alone. It starts with the relative
    error the scenario gives its single follower, xi_0 = x_1(0) - x_2(0) - d.
    """
    if sc.formation is None:
        return [(None, sc)]
    return [(f"follower_{i}", dataclasses.replace(sc, d=di, x2_0=sc.x2_0 + (sc.d - di)))
            for i, di in enumerate(slot_layout(sc.formation, sc.d, sc.k), start=1)]


def follower_csv_path(path, name):
    """FILE with _<name> before its extension, as cf_sim names a formation's files."""
    root, ext = os.path.splitext(path)
    return f"{root}_{name}{ext}"


def min_pair_separation(runs, k):
    """Smallest distance between any two agents (the leader and the followers) on the grid."""
    points = [np.vstack([runs[0][2][f"leader_p_{i}"] for i in range(k)])]
    points += [np.vstack([cols[f"follower_p_{i}"] for i in range(k)]) for _, _, cols, _ in runs]
    best = math.inf
    for j in range(1, len(points)):
        for i in range(j):
            best = min(best, float(np.min(np.linalg.norm(points[j] - points[i], axis=0))))
    return best


def main(argv=None):
    args = parse_args(argv)
    try:
        sc = load_scenario(args.scenario, args.overrides)
    except ScenarioError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    runs = []
    for name, fsc in follower_scenarios(sc):
        try:
            grid, Z, modes, wall, _ = simulate(fsc, args.method, args.rtol, args.atol,
                                               args.max_step)
        except (RuntimeError, ValueError) as exc:
            print(f"{PROG}: error: {name + ': ' if name else ''}{exc}", file=sys.stderr)
            return 1
        cols = signals_on_grid(fsc, grid, Z, modes)
        if args.csv:
            path = follower_csv_path(args.csv, name) if name else args.csv
            try:
                write_csv(path, cols)
            except OSError as exc:
                print(f"{PROG}: error: cannot write {path}: {exc.strerror}", file=sys.stderr)
                return 1
        line = " ".join(f"{key}={value:.9g}" for key, value in summary(fsc, cols, wall).items())
        print(f"{name} target=leader {line}" if name else line, flush=True)
        runs.append((name, fsc, cols, wall))
    if sc.formation is not None:
        fm = sc.formation
        print(f"formation followers={fm.followers} topology={fm.topology} shape={fm.shape} "
              f"slots={fm.slots} min_pair_separation={min_pair_separation(runs, sc.k):.9g} "
              f"wall_s={sum(r[3] for r in runs):.9g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
