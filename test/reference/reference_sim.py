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
chain of more followers is refused (exit 2) but by the sampled loop (below). Follower i
runs the pair's loop on its own d_i (doc/formations.md: line i d; V ceil(i/2) R(+-half_angle) d, + for odd i), with its
own xi_max, and starts with the scenario's xi_0; the followers do not interact, so each
is simulated alone. The output is then cf_sim's: a line
``follower_<i> target=leader max_xi=..`` per follower, then
``formation followers=.. topology=.. shape=.. slots=.. min_pair_separation=.. wall_s=..``
(the smallest distance between any two agents, leader included, on the grid); --csv FILE
writes FILE with _follower_<i> before its extension, per follower.

The formation line also gives ``perimeter=`` (alpha ||d|| of the scenario's d),
``min_neighbour_separation=`` (over the pairs of which neither looks at the other),
``pairs_inside_perimeter=`` and ``neighbour_pairs_inside_perimeter=`` (the pairs whose smallest
distance on the grid is below the perimeter), as cf_sim's does.

World and neighbours: the sampled loop. The section ``world`` (doc/formations.md, "A world that
can hurt") and ``formation.neighbours`` ((N1)-(N3) of doc/formations.md, "Neighbours") act per
control tick, so a scenario with either (or any scenario with --sampled) is not integrated in
continuous time but run as the sampled recursion of doc/math.md ("Follower command",
"Discretisation", "Offline simulator (cf_sim)"), every agent together (a star or a chain of
world slots; turning slots are refused). At tick t_k = k T, T = 1 / control_rate, with every
agent's true state x_j(t_k) and follower i looking at agent t(i) (0 the leader)::

    xi_i   = x_t(i) - x_i - d_i,   y = C (xi_i + noise_k)        noise entry e: sigma_e
             N(seed, 4 i + 1, k n + e) (sigma: position on the k position entries, else velocity)
    xi_hat = pinv(C) y moved into ||.|| <= xi_max at k = 0 (or 0: initial_estimate: zero)
    u      = sat(G y + u_a + u_ff, controller.acceleration_limit), u_a as above (0 tracker off)
    u      = u_prev + clamp(u - u_prev, jerk_limit T)            (controller.jerk_limit)
    u      = the projection (N3) of u (formation.neighbours), below
    xi_hat over [t_k, t_k+1]: `substeps` RK4 steps of the projected drift above with y, w and
           the augmentation held (u_a, or u - G y - u_ff where saturation, the rate limit or the
           projection changed the command), after each step moved back into ||.|| <= xi_max
    s_k    = sat(u, a_max of the vehicle);  z_k = z_k-1 + (1 - exp(-T / tau)) (s_k - z_k-1)
             (z_k = s_k for tau = 0, z_-1 = 0);  the plant is driven by g z_k over [t_k, t_k+1)
    plants exactly over [t_k, t_k+1] (x(t + h) = Phi(h) x + Psi(h) v, v constant), the period
           cut at the agent's own pulse edges: the leader's u_1(t_k) held and its disturbance
           pulses; follower i's pulses (world.followers and its gusts) and its sinusoids, these
           taken at the middle of each piece

u_prev is the command of the tick before (0 before the first). Gusts of follower i are drawn
from stream 4 i in the order of doc/formations.md (gust_pulses()); U and N as there
(uniform_draw(), normal_draws()). The summary figures use the true xi_i.

(N1)-(N3): follower i senses every other agent j within `radius` (its own target included, with
rho_j = alpha ||d_i||, every other with rho = perimeter); with p = p_i - p_j, v = v_i - v_j,
c = ||p||, n = p / c (the x axis at c = 0), s = -n.v and v_perp^2 = max(0, ||v||^2 - (n.v)^2):
beyond rho_j h = sqrt(2 a_b (c - rho_j)) - s and b = a_b s / sqrt(2 a_b (c - rho_j)) - v_perp^2 / c
+ A_n - omega h, else h = -inf and b = a_b + A_n. The half-space n.u >= b is dropped where b is
not finite or b <= -a_max (a_max = controller.acceleration_limit), and of the rest the
max_neighbours most urgent are kept (smaller h first, ties by smaller c). u is replaced by its
Euclidean projection onto the ball ||u|| <= a_max and the kept half-spaces, computed exactly by
enumerating active sets (nearest_point()); if that set is empty, the half-spaces are added in
priority order and any whose addition empties it is dropped (project_command()). Its CSV adds
u_applied_* (g z), noise_*, and per tick saturated, rate_limited, projected, kept, dropped.

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

The barrier filter: with controller.safety_filter (the tracker off) the sampled loop replaces
the projection (N3) by the filter (B1)-(B3) of doc/math.md, barrier_reference.py; its summary
line adds barrier_ticks and barrier_infeasible_ticks, its CSV barrier_infeasible.

Usage::

    reference_sim.py SCENARIO.yaml [--set key=value]... [--method LSODA]
                     [--rtol 1e-6] [--atol 1e-9] [--max-step S] [--csv FILE] [--sampled]

(--method, --rtol, --atol and --max-step are the continuous loop's; the sampled loop has none.)
controller.acceleration_limit and controller.jerk_limit are accepted by the sampled loop only.

Exit codes: 0 success, 1 integration failure, 2 bad command line or scenario.
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import math
import os
import sys
import time
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np
import yaml
from scipy.integrate import solve_ivp
from scipy.linalg import expm, solve_continuous_lyapunov

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import barrier_reference  # noqa: E402  (beside this file)

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
_VEHICLE = {"acceleration_limit": None, "input_gain": None, "actuator_lag": None}
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
        "acceleration_limit": None,     # sampled loop only (world, neighbours, --sampled)
        "jerk_limit": None,             # sampled loop only
        "safety_filter": barrier_reference.SCHEMA,   # sampled loop only (barrier_reference.py)
    },
    "leader": {
        "initial_state": None,
        "input": {"pulses": [_PULSE], "sinusoids": [_SINUSOID]},
        "disturbance": [_PULSE],
    },
    "follower": {"initial_state": None},
    "simulation": {"duration": None},
    "world": {
        "seed": None,
        "vehicle": dict(_VEHICLE),
        "followers": [{"index": None, "disturbance": [_PULSE], "sinusoids": [_SINUSOID],
                       "vehicle": dict(_VEHICLE)}],
        "gusts": {"rate": None, "magnitude": None, "min_duration": None, "max_duration": None,
                  "start": None, "end": None},
        "measurement_noise": {"position": None, "velocity": None},
    },
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
        "neighbours": {
            "radius": None,
            "perimeter": None,
            "braking_acceleration": None,
            "neighbour_acceleration": None,
            "rate": None,
            "max_neighbours": None,
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
    acceleration_limit: float = math.inf   # controller.acceleration_limit (sampled loop)
    jerk_limit: float = math.inf           # controller.jerk_limit (sampled loop)
    world: World = None             # the section world (sampled loop); None without it
    substeps: int = 1               # controller.estimator.substeps (sampled loop)
    sampled: bool = False           # run the sampled loop (world, neighbours or --sampled)
    safety_filter: float = None     # controller.safety_filter's rate (1/s); None without it

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
class Neighbours:
    """formation.neighbours: the command projection (N1)-(N3) (sampled loop only)."""

    radius: float = math.inf            # m: farther agents are not sensed
    perimeter: float = math.nan         # rho (m); nan: alpha ||d|| of the scenario's d
    braking_acceleration: float = 1.0   # a_b (m/s^2), > 0
    neighbour_acceleration: float = 0.0  # A_n (m/s^2), >= 0
    rate: float = 2.0                   # omega (1/s), > 0
    max_neighbours: int = 8             # the most urgent half-spaces kept, 1 .. 32


@dataclass(frozen=True)
class Formation:
    """The scenario's formation section: followers that all look at the leader (the continuous
    loop), or a star or chain of world slots (the sampled loop)."""

    followers: int = 1
    topology: str = "star"
    shape: str = "line"
    half_angle: float = math.pi / 6.0   # rad, each arm of a V to d
    slots: str = "world"                # world | turning
    turning: Turning = field(default_factory=Turning)
    neighbours: Neighbours = None       # formation.neighbours; None without it


def parse_formation(node, double_integrator, k, sampled=False):
    """The formation section, or None without one.

    Covered: a star (every follower looks at the leader, so that each runs the
    pair's loop on its own d_i and is simulated alone) and the single follower of
    either topology. A chain of more than one follower is refused, unless the loop is
    the sampled one (sampled: a world or neighbours section, or --sampled), which simulates
    every agent together.
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
    if topology == "chain" and followers > 1 and not sampled:
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
    neighbours = parse_neighbours(node.get("neighbours"), "neighbours" in node,
                                  double_integrator, k)
    return Formation(followers=followers, topology=topology, shape=shape,
                     half_angle=half_angle, slots=slots, turning=Turning(**values),
                     neighbours=neighbours)


def as_limit(v, path):
    """A number > 0 or .inf (a limit that may be absent)."""
    if not _is_number(v) or math.isnan(float(v)) or not float(v) > 0.0:
        raise ScenarioError(f"{path}: expected a number > 0 or .inf, got {v!r}")
    return float(v)


def parse_neighbours(node, given, double_integrator, k):
    """formation.neighbours (N1)-(N3), or None without it. The perimeter's default, alpha ||d||
    of the scenario's d, is filled in by build_scenario()."""
    if not given:
        return None
    node = node or {}
    if not isinstance(node, dict):
        raise ScenarioError("formation.neighbours: expected a mapping")
    if not (double_integrator and 1 <= k <= 3):
        raise ScenarioError("formation.neighbours: needs a double_integrator model of 1 to 3 axes")
    path = "formation.neighbours"
    radius = node.get("radius", math.inf)
    if not _is_number(radius) or math.isnan(float(radius)) or not float(radius) >= 0.0:
        raise ScenarioError(f"{path}.radius: expected a number >= 0 or .inf")
    values = {"radius": float(radius)}
    if node.get("perimeter") is not None:
        values["perimeter"] = as_float(node["perimeter"], f"{path}.perimeter")
        if not values["perimeter"] >= 0.0:
            raise ScenarioError(f"{path}.perimeter: must be >= 0")
    for key, low, strict in (("braking_acceleration", 0.0, True),
                             ("neighbour_acceleration", 0.0, False), ("rate", 0.0, True)):
        if node.get(key) is not None:
            value = as_float(node[key], f"{path}.{key}")
            if not (value > low if strict else value >= low):
                raise ScenarioError(f"{path}.{key}: must be {'>' if strict else '>='} {low:g}")
            values[key] = value
    if node.get("max_neighbours") is not None:
        count = node["max_neighbours"]
        if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= 32:
            raise ScenarioError(f"{path}.max_neighbours: expected an integer in 1 .. 32")
        values["max_neighbours"] = count
    return Neighbours(**values)


@dataclass(frozen=True)
class Vehicle:
    """A follower's true vehicle (world.vehicle): s = sat(u, acceleration_limit), a first-order
    lag of actuator_lag s sampled at the control period, driven with input_gain * z."""

    acceleration_limit: float = math.inf
    input_gain: float = 1.0
    actuator_lag: float = 0.0


@dataclass(frozen=True)
class Gusts:
    """world.gusts: a Poisson process of rate per follower over [start, end)."""

    rate: float = 0.0
    magnitude: float = 0.0
    min_duration: float = 0.5
    max_duration: float = 2.0
    start: float = 0.0
    end: float = math.inf


@dataclass(frozen=True)
class FollowerWorld:
    """world.followers.<j>: what differs for follower `index`."""

    index: int
    disturbances: list          # (start, end, n-vector), pulses on the state derivative
    sinusoids: list             # (n-vector amplitude, frequency, phase)
    vehicle: Vehicle


@dataclass(frozen=True)
class World:
    """The section world (sampled loop only)."""

    seed: int = 0
    vehicle: Vehicle = field(default_factory=Vehicle)
    followers: dict = field(default_factory=dict)     # index -> FollowerWorld
    gusts: Gusts = field(default_factory=Gusts)
    noise_position: float = 0.0
    noise_velocity: float = 0.0


def _mapping(node, path):
    if node is None:
        return {}
    if not isinstance(node, dict):
        raise ScenarioError(f"{path}: expected a mapping")
    return node


def _vehicle(node, path, base):
    node = _mapping(node, path)
    limit = as_limit(node.get("acceleration_limit", base.acceleration_limit),
                     f"{path}.acceleration_limit")
    gain = as_float(node.get("input_gain", base.input_gain), f"{path}.input_gain")
    if not gain > 0.0:
        raise ScenarioError(f"{path}.input_gain: must be > 0")
    lag = as_float(node.get("actuator_lag", base.actuator_lag), f"{path}.actuator_lag")
    if not lag >= 0.0:
        raise ScenarioError(f"{path}.actuator_lag: must be >= 0")
    return Vehicle(acceleration_limit=limit, input_gain=gain, actuator_lag=lag)


def parse_world(node, n, followers):
    """The section world, or None without it (followers: how many the run has)."""
    node = _mapping(node, "world")
    seed = node.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2 ** 64:
        raise ScenarioError(f"world.seed: expected a whole number >= 0, got {seed!r}")
    vehicle = _vehicle(node.get("vehicle"), "world.vehicle", Vehicle())
    items = node.get("followers") or []
    if not isinstance(items, list):
        raise ScenarioError("world.followers: expected a list")
    per = {}
    for j, item in enumerate(items):
        path = f"world.followers.{j}"
        item = _mapping(item, path)
        index = get(item, "index", path)
        if isinstance(index, bool) or not isinstance(index, int) or not 1 <= index <= followers:
            raise ScenarioError(f"{path}.index: expected an integer in 1 .. {followers}")
        if index in per:
            raise ScenarioError(f"{path}.index: follower {index} is given twice")
        sins = []
        raw_sins = item.get("sinusoids") or []
        if not isinstance(raw_sins, list):
            raise ScenarioError(f"{path}.sinusoids: expected a list")
        for q, sn in enumerate(raw_sins):
            spath = f"{path}.sinusoids.{q}"
            sn = _mapping(sn, spath)
            sins.append((as_vector(get(sn, "amplitude", spath), f"{spath}.amplitude", n),
                         as_float(get(sn, "frequency", spath), f"{spath}.frequency"),
                         as_float(sn.get("phase", 0.0), f"{spath}.phase")))
        per[index] = FollowerWorld(
            index=index, disturbances=_pulses(item.get("disturbance"), f"{path}.disturbance", n),
            sinusoids=sins, vehicle=_vehicle(item.get("vehicle"), f"{path}.vehicle", vehicle))
    gnode = _mapping(node.get("gusts"), "world.gusts")
    g = {}
    for key, default in vars(Gusts()).items():
        value = gnode.get(key, default)
        if key == "end":
            if not _is_number(value) or math.isnan(float(value)):
                raise ScenarioError("world.gusts.end: expected a number or .inf")
            g[key] = float(value)
        else:
            g[key] = as_float(value, f"world.gusts.{key}")
    gusts = Gusts(**g)
    if not (gusts.rate >= 0.0 and gusts.magnitude >= 0.0):
        raise ScenarioError("world.gusts: rate and magnitude must be >= 0")
    if not gusts.min_duration > 0.0:
        raise ScenarioError("world.gusts.min_duration: must be > 0")
    if not gusts.max_duration >= gusts.min_duration:
        raise ScenarioError("world.gusts.max_duration: must be >= min_duration")
    if not gusts.end > gusts.start:
        raise ScenarioError("world.gusts.end: must be > start")
    noise = _mapping(node.get("measurement_noise"), "world.measurement_noise")
    sigma = {}
    for key in ("position", "velocity"):
        sigma[key] = as_float(noise.get(key, 0.0), f"world.measurement_noise.{key}")
        if not sigma[key] >= 0.0:
            raise ScenarioError(f"world.measurement_noise.{key}: must be >= 0")
    return World(seed=seed, vehicle=vehicle, followers=per, gusts=gusts,
                 noise_position=sigma["position"], noise_velocity=sigma["velocity"])


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


def build_scenario(raw, sampled=False):
    """Validate the raw YAML tree and return a Scenario.

    The loop is the sampled one (Scenario.sampled) with sampled set (--sampled), a section
    world, formation.neighbours or controller.safety_filter; else the continuous one, which
    refuses controller.acceleration_limit and controller.jerk_limit (defined per control period
    here).
    """
    if not isinstance(raw, dict):
        raise ScenarioError("the scenario must be a YAML mapping")
    check_keys(raw, SCHEMA)
    fnode = raw.get("formation")
    cnode = raw.get("controller")
    sampled = bool(sampled or "world" in raw
                   or (isinstance(fnode, dict) and "neighbours" in fnode)
                   or (isinstance(cnode, dict) and "safety_filter" in cnode))

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
    safety_filter = barrier_reference.parse(ctl.get("safety_filter"), tracker,
                                            double_integrator, ScenarioError)

    info = ctl.get("leader_information") or {}
    info_command = as_bool(info.get("command", False), "controller.leader_information.command")
    info_estimator = as_bool(info.get("estimator", False),
                             "controller.leader_information.estimator")
    info_disturbance = as_bool(info.get("disturbance", False),
                               "controller.leader_information.disturbance")
    limits = {}
    for key in ("acceleration_limit", "jerk_limit"):
        if ctl.get(key) is None:
            limits[key] = math.inf
            continue
        limits[key] = as_limit(ctl[key], f"controller.{key}")
        if not sampled and limits[key] < math.inf:
            raise ScenarioError(
                f"controller.{key}: covered by the sampled loop only (a section world or "
                "formation.neighbours, or --sampled)")

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

    formation = parse_formation(raw.get("formation"), double_integrator, k, sampled)
    if formation is not None and formation.neighbours is not None \
            and math.isnan(formation.neighbours.perimeter):
        formation = dataclasses.replace(formation, neighbours=dataclasses.replace(
            formation.neighbours, perimeter=alpha * float(np.linalg.norm(d))))
    if sampled and formation is not None and formation.slots != "world":
        raise ScenarioError(
            f"formation.slots = {formation.slots}: the sampled loop (world, neighbours) covers "
            "world slots only")
    if sampled and formation is not None and formation.topology == "chain" \
            and formation.followers > 1 and (info_command or info_estimator):
        raise ScenarioError(
            "controller.leader_information: not covered by the reference for a chain (a "
            "follower's target is then a follower, whose command it is not told)")
    world = parse_world(raw.get("world"), n, formation.followers if formation else 1) \
        if "world" in raw else None

    return Scenario(A=A, B=B, C=C, k=k, double_integrator=double_integrator,
                    control_rate=control_rate, d=d, alpha=alpha, epsilon=epsilon,
                    G=G, L=L, Q=Q, initial_estimate=init, tracker=tracker, Ge=Ge, S21=S21,
                    info_command=info_command, info_estimator=info_estimator,
                    info_disturbance=info_disturbance,
                    x1_0=x1_0, x2_0=x2_0, input_pulses=input_pulses, sinusoids=sinusoids,
                    disturbances=disturbances, duration=duration, formation=formation,
                    acceleration_limit=limits["acceleration_limit"],
                    jerk_limit=limits["jerk_limit"], world=world, substeps=substeps or 1,
                    sampled=sampled, safety_filter=safety_filter)


def load_scenario(path, overrides=(), sampled=False):
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
    return build_scenario(raw, sampled)


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
# Sampled loop: the section world and formation.neighbours
# --------------------------------------------------------------------------

_MASK64 = (1 << 64) - 1


def splitmix64(x):
    """splitmix64 of an integer, mod 2^64."""
    z = (x + 0x9E3779B97F4A7C15) & _MASK64
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK64
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK64
    return z ^ (z >> 31)


def uniform_draw(seed, stream, count):
    """U(seed, stream, count) = (splitmix64(splitmix64(seed) ^ (stream << 40 | count)) >> 11)
    2^-53, in [0, 1)."""
    key = ((stream << 40) | count) & _MASK64
    return (splitmix64(splitmix64(seed) ^ key) >> 11) * 2.0 ** -53


def uniform_draws(seed, stream, counts):
    """uniform_draw() for an array of counts (numpy's uint64 arithmetic wraps mod 2^64)."""
    counts = np.asarray(counts, dtype=np.uint64)
    x = np.uint64(splitmix64(seed)) ^ (np.uint64((stream << 40) & _MASK64) | counts)
    with np.errstate(over="ignore"):
        z = x + np.uint64(0x9E3779B97F4A7C15)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        z = z ^ (z >> np.uint64(31))
    return (z >> np.uint64(11)).astype(np.float64) * 2.0 ** -53


def normal_draws(seed, stream, counts):
    """N(seed, stream, c) = sqrt(-2 ln(1 - U(2c))) cos(2 pi U(2c + 1)) (Box-Muller)."""
    c = np.asarray(counts, dtype=np.uint64)
    ua = uniform_draws(seed, stream, np.uint64(2) * c)
    ub = uniform_draws(seed, stream, np.uint64(2) * c + np.uint64(1))
    return np.sqrt(-2.0 * np.log(1.0 - ua)) * np.cos(2.0 * math.pi * ub)


def gust_pulses(world, index, B, duration):
    """The gusts of follower `index` as pulses (start, end, n-vector B g), stream 4 index.

    Per gust, in this order of draws: the gap -ln(1 - U)/rate (from max(0, start)), the
    duration min + U (max - min), the strength U magnitude, then m entries
    sqrt(-2 ln(1 - U_a)) cos(2 pi U_b) of the direction (drawn again while of norm 0). A gust
    starting at or after min(end, duration) ends the list; the others are cut there.
    """
    g = world.gusts
    if not (g.rate > 0.0 and g.magnitude > 0.0):
        return []
    m = B.shape[1]
    count = 0

    def draw():
        nonlocal count
        value = uniform_draw(world.seed, 4 * index, count)
        count += 1
        return value

    stop = min(g.end, duration)
    t = max(0.0, g.start)
    out = []
    while True:
        t += -math.log(1.0 - draw()) / g.rate
        length = g.min_duration + draw() * (g.max_duration - g.min_duration)
        strength = draw() * g.magnitude
        while True:
            direction = np.empty(m)
            for e in range(m):
                ua = draw()
                ub = draw()
                direction[e] = math.sqrt(-2.0 * math.log(1.0 - ua)) * math.cos(2.0 * math.pi * ub)
            norm = float(np.linalg.norm(direction))
            if norm > 0.0:
                break
        if t >= stop:
            return out
        out.append((t, min(t + length, stop), B @ (strength * direction / norm)))


_SUBSETS = {}


def _subsets(q, k):
    """Index arrays (C, s) of the subsets of s of q half-spaces, s = 1 .. min(k, q)."""
    key = (q, k)
    if key not in _SUBSETS:
        _SUBSETS[key] = [np.array(list(itertools.combinations(range(q), size)),
                                  dtype=int).reshape(-1, size)
                         for size in range(1, min(k, q) + 1)]
    return _SUBSETS[key]


def nearest_point(u, normals, bounds, amax, tol=1e-10):
    """The point of {||x|| <= amax} cap {normals x >= bounds} (unit normals) nearest to u, or
    None if the set is empty.

    Exact, by enumerating active sets: the nearest point satisfies its KKT conditions with a
    linearly independent set S of active half-spaces (|S| <= k) and the ball active or not, so
    it is the candidate of one of them: u's projection onto the affine set {N_S x = b_S}
    (x0 + P u, x0 the set's point nearest 0, P the projector onto N_S's null space), or the
    point of that set on the sphere along P u, x0 + sqrt(amax^2 - |x0|^2) P u / |P u|. Every
    feasible candidate is at least as far from u as the nearest point, so the nearest feasible
    candidate is it (feasible: within tol, relative, of every half-space and the sphere).
    """
    k = u.size
    ball = amax < math.inf
    cands = [u[None, :]]
    nu = float(np.linalg.norm(u))
    if ball and nu > 0.0:
        cands.append((u * (amax / nu))[None, :])
    for idx in _subsets(bounds.size, k):
        size = idx.shape[1]
        Ns, bs = normals[idx], bounds[idx]                              # (C, s, k), (C, s)
        if size == k:                                                   # vertices
            ok = np.abs(np.linalg.det(Ns)) > 1e-7 if size > 1 else np.ones(len(idx), bool)
            if np.any(ok):
                cands.append(np.linalg.solve(Ns[ok], bs[ok][:, :, None])[:, :, 0])
            continue
        if size == 1:
            Minv = np.ones((len(idx), 1, 1))
        else:
            M = Ns @ Ns.transpose(0, 2, 1)
            ok = np.abs(np.linalg.det(M)) > 1e-14
            Ns, bs, M = Ns[ok], bs[ok], M[ok]
            if not len(M):
                continue
            Minv = np.linalg.inv(M)
        x0 = np.einsum("csk,cs->ck", Ns, np.einsum("cst,ct->cs", Minv, bs))
        Pu = u - np.einsum("csk,cs->ck", Ns, np.einsum("cst,ct->cs", Minv, Ns @ u))
        cands.append(x0 + Pu)
        if ball:
            r2 = amax * amax - np.sum(x0 * x0, axis=1)
            nw = np.linalg.norm(Pu, axis=1)
            good = (r2 >= 0.0) & (nw > 0.0)
            if np.any(good):
                cands.append(x0[good] + (np.sqrt(r2[good]) / nw[good])[:, None] * Pu[good])
    X = np.vstack(cands)
    feasible = np.all(X @ normals.T >= bounds - tol * np.maximum(1.0, np.abs(bounds)), axis=1)
    if ball:
        feasible &= np.linalg.norm(X, axis=1) <= amax * (1.0 + tol)
    if not np.any(feasible):
        return None
    X = X[feasible]
    return X[int(np.argmin(np.linalg.norm(X - u, axis=1)))]


def project_command(u, normals, bounds, amax):
    """(N3): u's Euclidean projection onto the ball ||x|| <= amax and the half-spaces (rows in
    priority order). If that set is empty, the half-spaces are taken in priority order, each
    dropped whose addition empties the set with the ball; the projection is onto the rest.
    Returns (projection, how many half-spaces were dropped)."""
    x = nearest_point(u, normals, bounds, amax)
    if x is not None:
        return x, 0
    keep = []
    witness = np.zeros_like(u)          # a point of the ball and the kept half-spaces
    for j in range(bounds.size):
        if bounds[j] > amax * (1.0 + 1e-10):
            continue                    # outside the ball
        if normals[j] @ witness >= bounds[j] - 1e-10 * max(1.0, abs(bounds[j])):
            keep.append(j)              # the witness is in it too
            continue
        trial = keep + [j]
        point = nearest_point(np.zeros_like(u), normals[trial], bounds[trial], amax)
        if point is not None:
            keep, witness = trial, point
    x = nearest_point(u, normals[keep], bounds[keep], amax)
    return x, bounds.size - len(keep)


def neighbour_halfspaces(nb, P, V, targets, own_perimeter, amax):
    """(N1), (N2) for every follower against every other agent, at once.

    P, V (F + 1, k) the agents' true positions and velocities (row 0 the leader); targets (F,)
    the agent each follower looks at. Returns (normals (F, F + 1, k), bounds b, urgency h,
    distance c, valid (F, F + 1)): follower i's half-space against agent j is normals.u >= b,
    valid where j is sensed (not i, c <= radius) and b is finite and > -amax.
    """
    F = len(targets)
    dp = P[1:, None, :] - P[None, :, :]
    dv = V[1:, None, :] - V[None, :, :]
    c = np.sqrt(np.sum(dp * dp, axis=2))
    safe_c = np.where(c > 0.0, c, 1.0)
    x_axis = np.zeros(P.shape[1])
    x_axis[0] = 1.0
    normals = np.where((c > 0.0)[:, :, None], dp / safe_c[:, :, None], x_axis)
    nv = np.sum(normals * dv, axis=2)
    closing = -nv                                                    # s
    v_perp2 = np.maximum(0.0, np.sum(dv * dv, axis=2) - nv * nv)
    rho = np.full(c.shape, nb.perimeter)
    rho[np.arange(F), targets] = own_perimeter
    outside = c > rho
    root = np.sqrt(2.0 * nb.braking_acceleration * np.where(outside, c - rho, 1.0))
    h = np.where(outside, root - closing, -math.inf)                                    # (N1)
    with np.errstate(invalid="ignore"):
        b = np.where(outside,
                     nb.braking_acceleration * closing / root - v_perp2 / safe_c
                     + nb.neighbour_acceleration - nb.rate * h,                         # (N2)
                     nb.braking_acceleration + nb.neighbour_acceleration)
    not_self = np.ones(c.shape, dtype=bool)
    not_self[np.arange(F), np.arange(1, F + 1)] = False
    valid = not_self & (c <= nb.radius) & np.isfinite(b) & (b > -amax)
    return normals, b, h, c, valid


def chain_layout(formation, d, k):
    """d_i of a chain (doc/formations.md): d for a line; R(+-half_angle) d for a V."""
    out = []
    for i in range(1, formation.followers + 1):
        if formation.shape == "line":
            out.append(d.copy())
            continue
        di = d.copy()
        di[:k] = rotate_z(d[:k], formation.half_angle if i % 2 else -formation.half_angle)
        out.append(di)
    return out


def formation_targets(formation):
    """The agent each follower looks at (0 the leader, i follower i)."""
    if formation is None:
        return [0]
    N = formation.followers
    if formation.topology == "star":
        return [0] * N
    lag = 1 if formation.shape == "line" else 2
    return [max(0, i - lag) for i in range(1, N + 1)]


class ExactStep:
    """x(t + delta) = Phi(delta) x + Psi(delta) v for x' = A x + v, v constant (cached)."""

    def __init__(self, A, double_integrator):
        self.A, self.di, self.cache = A, double_integrator, {}

    def __call__(self, delta):
        hit = self.cache.get(delta)
        if hit is None:
            n = self.A.shape[0]
            if self.di:                      # A^2 = 0
                hit = (np.eye(n) + self.A * delta, np.eye(n) * delta + self.A * (0.5 * delta ** 2))
            else:
                big = np.zeros((2 * n, 2 * n))
                big[:n, :n], big[:n, n:] = self.A, np.eye(n)
                E = expm(big * delta)
                hit = (E[:n, :n], E[:n, n:])
            if len(self.cache) < 4096:
                self.cache[delta] = hit
        return hit


def _piecewise(pulses, sinusoids, grid, n):
    """Per period [t_k, t_k+1): the pulses' and sinusoids' sum at its middle (N, n), whether a
    pulse edge lies inside it (N,), and the sorted edges."""
    edges = np.array(sorted({e for a, b, _ in pulses for e in (a, b)}))
    mids = 0.5 * (grid[:-1] + grid[1:])
    value = (pulse_sum(pulses, mids, n) + sinusoid_sum(sinusoids, mids, n)).T
    if edges.size:
        inside = (np.searchsorted(edges, grid[1:], "left")
                  > np.searchsorted(edges, grid[:-1], "right"))
    else:
        inside = np.zeros(mids.size, dtype=bool)
    return value, inside, edges


def _segments(edges, a, b):
    """[a, b] cut at the edges strictly inside it."""
    lo, hi = np.searchsorted(edges, a, "right"), np.searchsorted(edges, b, "left")
    return [a] + [float(e) for e in edges[lo:hi]] + [b]


def advance(x, drive, pulses, sinusoids, edges, a, b, step, B, value_mid, cut):
    """One agent over [a, b]: the input `drive` (m) held, the pulses and sinusoids (n) constant
    on each piece of the period cut at the pulse edges, at its middle."""
    if not cut:
        Phi, Psi = step(b - a)
        return Phi @ x + Psi @ (B @ drive + value_mid)
    cuts = _segments(edges, a, b)
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        mid = 0.5 * (lo + hi)
        v = B @ drive + pulse_sum(pulses, mid, B.shape[0])[:, 0]
        if sinusoids:
            v = v + sinusoid_sum(sinusoids, mid, B.shape[0])[:, 0]
        Phi, Psi = step(hi - lo)
        x = Phi @ x + Psi @ v
    return x


def simulate_sampled(sc):
    """The sampled loop of doc/math.md ('Follower command', 'Discretisation', 'Offline
    simulator') with the section world and formation.neighbours (N1)-(N3), every agent at once.

    Returns (names, targets (F,), per-follower column dicts, pair minima (F+1, F+1), wall s).
    """
    wall0 = time.perf_counter()
    fm = sc.formation
    n, m, k = sc.n, sc.m, sc.k
    T = 1.0 / sc.control_rate
    grid = time_grid(sc)
    N = grid.size - 1
    targets = np.array(formation_targets(fm))
    F = targets.size
    if fm is None:
        D = np.array([sc.d])
    elif fm.topology == "chain":
        D = np.array(chain_layout(fm, sc.d, k))
    else:
        D = np.array(slot_layout(fm, sc.d, k))
    d_norm = np.linalg.norm(D, axis=1)
    xi_max = (1.0 - sc.alpha) * d_norm
    own_perimeter = sc.alpha * d_norm
    world = sc.world if sc.world is not None else World()
    nb = fm.neighbours if fm is not None else None

    # Agents: row 0 the leader, row i follower i; each follower starts with the scenario's xi_0.
    xi0 = sc.x1_0 - sc.x2_0 - sc.d
    X = np.zeros((F + 1, n))
    X[0] = sc.x1_0
    for i in range(1, F + 1):
        X[i] = X[targets[i - 1]] - D[i - 1] - xi0

    # The world of each follower: vehicle, pulses (its own and its gusts), sinusoids, noise.
    vehicles, pulses, sines = [], [], []
    for i in range(1, F + 1):
        fw = world.followers.get(i)
        vehicles.append(fw.vehicle if fw else world.vehicle)
        pulses.append((list(fw.disturbances) if fw else [])
                      + gust_pulses(world, i, sc.B, sc.duration))
        sines.append(list(fw.sinusoids) if fw else [])
    v_limit = np.array([v.acceleration_limit for v in vehicles])
    v_gain = np.array([v.input_gain for v in vehicles])
    v_lag = np.array([v.actuator_lag for v in vehicles])
    v_beta = np.where(v_lag > 0.0, -np.expm1(-T / np.where(v_lag > 0.0, v_lag, 1.0)), 1.0)
    sigma = np.where(np.arange(n) < k, world.noise_position, world.noise_velocity)
    if np.any(sigma > 0.0):
        counts = (np.arange(N + 1, dtype=np.uint64)[:, None] * np.uint64(n)
                  + np.arange(n, dtype=np.uint64)[None, :])
        noise = np.stack([sigma * normal_draws(world.seed, 4 * i + 1, counts)
                          for i in range(1, F + 1)])                    # (F, N + 1, n)
    else:
        noise = np.zeros((F, N + 1, n))
    follower_drive = [_piecewise(pulses[i], sines[i], grid, n) for i in range(F)]
    leader_drive = _piecewise(sc.disturbances, [], grid, n)
    u1_grid = (pulse_sum(sc.input_pulses, grid, m) + sinusoid_sum(sc.sinusoids, grid, m)).T
    ud_grid = pulse_sum(sc.disturbances, grid, n).T
    step = ExactStep(sc.A, sc.double_integrator)

    XH = np.zeros((F, n))
    U_prev = np.zeros((F, m))
    Z = np.zeros((F, m))                          # the vehicles' lag states, z_{-1} = 0
    Fm = sc.F                                     # A_c + L C
    delta = T / sc.substeps
    xm2 = xi_max ** 2
    rec = {key: np.zeros((N + 1, F, size)) for key, size in
           (("xi", n), ("xi_hat", n), ("x", n), ("target", n), ("u", m), ("u_baseline", m),
            ("u_tracker", m), ("u_applied", m), ("noise", n))}
    rec_f = {key: np.zeros((N + 1, F)) for key in ("f", "kept", "dropped", "projected",
                                                   "saturated", "rate_limited",
                                                   "barrier_infeasible")}
    pair_min = np.full((F + 1, F + 1), math.inf)
    leader_told = np.where(targets == 0, 1.0, 0.0)[:, None]

    def field_at(xh, c):
        hh = xh @ Fm.T + c
        fval = ((1.0 + sc.epsilon) * np.sum(xh * xh, axis=1) - xm2) / (sc.epsilon * xm2)
        grad_h = np.sum(xh * hh, axis=1)
        active = (fval > 0.0) & (grad_h > 0.0)
        gx = xh @ sc.Gamma_inv.T
        denom = np.sum(xh * gx, axis=1)
        scale = np.where(active, fval * grad_h / np.where(active, denom, 1.0), 0.0)
        return hh - gx * scale[:, None]

    for tick in range(N + 1):
        t = grid[tick]
        pos = X[:, :k]
        diff = pos[:, None, :] - pos[None, :, :]
        pair_min = np.minimum(pair_min, np.sqrt(np.sum(diff * diff, axis=2)))
        xi = X[targets] - X[1:] - D
        y = (xi + noise[:, tick]) @ sc.C.T
        if tick == 0:
            if sc.initial_estimate == "zero":
                XH = np.zeros((F, n))
            else:
                XH = y @ np.linalg.pinv(sc.C).T
                norm = np.linalg.norm(XH, axis=1)
                over = norm > xi_max
                XH[over] *= (xi_max[over] / norm[over])[:, None]
        rec["xi"][tick], rec["xi_hat"][tick] = xi, XH
        rec["x"][tick], rec["target"][tick], rec["noise"][tick] = X[1:], X[targets], noise[:, tick]
        rec_f["f"][tick] = (((1.0 + sc.epsilon) * np.sum(XH * XH, axis=1) - xm2)
                            / (sc.epsilon * xm2))

        u1 = u1_grid[tick]
        a1 = u1 + sc.B_pinv @ ud_grid[tick] if sc.info_disturbance else u1
        uff = leader_told * a1 if sc.info_command else np.zeros((F, m))
        w = (leader_told * a1 - uff) @ sc.B.T if sc.info_estimator else np.zeros((F, n))
        yh = XH @ sc.C.T
        ua = ((y - yh) @ sc.Ge.T + yh @ sc.S21.T) if sc.tracker else np.zeros((F, m))
        ub = y @ sc.G.T
        u = ub + ua + uff
        norm = np.linalg.norm(u, axis=1)
        saturated = norm > sc.acceleration_limit
        u[saturated] *= (sc.acceleration_limit / norm[saturated])[:, None]
        rate_limited = np.zeros(F, dtype=bool)
        if sc.jerk_limit < math.inf:
            du = u - U_prev
            dn = np.linalg.norm(du, axis=1)
            rate_limited = dn > sc.jerk_limit * T
            u[rate_limited] = (U_prev[rate_limited] + du[rate_limited]
                               * (sc.jerk_limit * T / dn[rate_limited])[:, None])
        projected = np.zeros(F, dtype=bool)
        if sc.safety_filter is not None:          # (B1)-(B3), barrier_reference.py
            sensed = None
            if nb is not None:
                _, _, urgency, dist, valid = neighbour_halfspaces(
                    nb, X[:, :k], X[:, k:2 * k], targets, own_perimeter, sc.acceleration_limit)
                sensed = (nb, valid, urgency, dist)
            u, projected, infeasible = barrier_reference.filter_commands(
                sc, sc.safety_filter, u, X, targets, own_perimeter, a1,
                sc.info_command or sc.info_estimator, sensed, nearest_point, project_command)
            rec_f["barrier_infeasible"][tick] = infeasible
        elif nb is not None:
            amax = sc.acceleration_limit
            normals, bounds, urgency, dist, valid = neighbour_halfspaces(
                nb, X[:, :k], X[:, k:2 * k], targets, own_perimeter, amax)
            along = np.einsum("ijk,ik->ij", normals, u)
            slack = 1e-12 * np.maximum(1.0, np.abs(bounds))
            for i in np.nonzero(np.any(valid & (along < bounds - slack), axis=1))[0]:
                idx = np.nonzero(valid[i])[0]
                order = np.lexsort((dist[i, idx], urgency[i, idx]))[:nb.max_neighbours]
                idx = idx[order]
                if not np.any(along[i, idx] < bounds[i, idx] - slack[i, idx]):
                    continue                          # only unkept half-spaces are violated
                x, dropped = project_command(u[i], normals[i, idx], bounds[i, idx], amax)
                rec_f["dropped"][tick, i] = dropped
                if not np.array_equal(x, u[i]):
                    u[i] = x
                    projected[i] = True
            rec_f["kept"][tick] = np.minimum(np.sum(valid, axis=1), nb.max_neighbours)
        U_prev = u.copy()
        acts = saturated | rate_limited | projected
        aug = np.where(acts[:, None], u - ub - uff, ua)        # the augmentation that acts
        rec["u"][tick], rec["u_baseline"][tick], rec["u_tracker"][tick] = u, ub, aug
        rec_f["projected"][tick], rec_f["saturated"][tick] = projected, saturated
        rec_f["rate_limited"][tick] = rate_limited

        # The true vehicles: saturation, lag, gain.
        s = u.copy()
        norm = np.linalg.norm(s, axis=1)
        over = norm > v_limit
        s[over] *= (v_limit[over] / norm[over])[:, None]
        Z = np.where((v_lag > 0.0)[:, None], Z + v_beta[:, None] * (s - Z), s)
        drive = v_gain[:, None] * Z
        rec["u_applied"][tick] = drive
        if tick == N:
            break

        # The estimator over the period: RK4 substeps with y, the augmentation and w held; an
        # estimate outside the hard sphere after a substep is scaled back onto it.
        c = w - aug @ sc.B.T - y @ sc.L.T
        for _ in range(sc.substeps):
            k1 = field_at(XH, c)
            k2 = field_at(XH + 0.5 * delta * k1, c)
            k3 = field_at(XH + 0.5 * delta * k2, c)
            k4 = field_at(XH + delta * k3, c)
            XH = XH + (delta / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            norm = np.linalg.norm(XH, axis=1)
            out = norm > xi_max
            XH[out] *= (xi_max[out] / norm[out])[:, None]

        # The plants, exactly over [t_k, t_k+1]: inputs held, pulses cut at their edges.
        a, b = t, grid[tick + 1]
        value, cut, edges = leader_drive
        X_next = np.empty_like(X)
        X_next[0] = advance(X[0], u1, sc.disturbances, [], edges, a, b, step, sc.B,
                            value[tick], cut[tick])
        Phi, Psi = step(b - a)
        plain = [i for i in range(F) if not follower_drive[i][1][tick]]
        if plain:
            mids = np.array([follower_drive[i][0][tick] for i in plain])
            V = drive[plain] @ sc.B.T + mids
            X_next[np.array(plain) + 1] = X[np.array(plain) + 1] @ Phi.T + V @ Psi.T
        for i in range(F):
            if follower_drive[i][1][tick]:
                value, cut, edges = follower_drive[i]
                X_next[i + 1] = advance(X[i + 1], drive[i], pulses[i], sines[i], edges, a, b,
                                        step, sc.B, value[tick], True)
        X = X_next
    wall = time.perf_counter() - wall0

    names = [f"follower_{i}" for i in range(1, F + 1)] if fm is not None else [None]
    runs = []
    for i in range(F):
        cols = {"t": grid}
        for e in range(n):
            cols[f"xi_{e}"] = rec["xi"][:, i, e]
        for e in range(n):
            cols[f"xi_hat_{e}"] = rec["xi_hat"][:, i, e]
        cols["norm_xi"] = np.linalg.norm(rec["xi"][:, i], axis=1)
        cols["norm_xi_hat"] = np.linalg.norm(rec["xi_hat"][:, i], axis=1)
        cols["xi_max"] = np.full(N + 1, xi_max[i])
        cols["xi_soft"] = np.full(N + 1, xi_max[i] / math.sqrt(1.0 + sc.epsilon))
        cols["f"] = rec_f["f"][:, i]
        for e in range(k):
            cols[f"leader_p_{e}"] = rec["target"][:, i, e]
        for e in range(k):
            cols[f"follower_p_{e}"] = rec["x"][:, i, e]
        if sc.double_integrator:
            for e in range(k):
                cols[f"leader_v_{e}"] = rec["target"][:, i, k + e]
            for e in range(k):
                cols[f"follower_v_{e}"] = rec["x"][:, i, k + e]
        cols["separation"] = np.linalg.norm(rec["target"][:, i, :k] - rec["x"][:, i, :k], axis=1)
        cols["perimeter"] = np.full(N + 1, own_perimeter[i])
        for name in ("u", "u_baseline", "u_tracker", "u_applied"):
            for e in range(m):
                cols[f"{name}_{e}"] = rec[name][:, i, e]
        for e in range(m):
            cols[f"leader_u_{e}"] = u1_grid[:, e]
        for e in range(n):
            cols[f"noise_{e}"] = rec["noise"][:, i, e]
        for name in ("saturated", "rate_limited", "projected", "kept", "dropped"):
            cols[name] = rec_f[name][:, i]
        if sc.safety_filter is not None:
            cols["barrier_infeasible"] = rec_f["barrier_infeasible"][:, i]
        runs.append((names[i], cols, xi_max[i]))
    return runs, targets, pair_min, wall


def pair_figures(pair_min, targets, perimeter):
    """The formation line's figures from the pairs' smallest distances (agents 0 .. F, 0 the
    leader): min_pair_separation, perimeter, min_neighbour_separation (pairs of which neither
    looks at the other), pairs_inside_perimeter and neighbour_pairs_inside_perimeter (pairs that
    came closer than the perimeter at some tick)."""
    agents = pair_min.shape[0]
    target_of = {i: int(targets[i - 1]) for i in range(1, agents)}
    every, neighbours = [], []
    for b in range(1, agents):
        for a in range(b):
            every.append(pair_min[a, b])
            if target_of.get(a) != b and target_of.get(b) != a:
                neighbours.append(pair_min[a, b])
    return {"min_pair_separation": min(every, default=math.inf),
            "perimeter": perimeter,
            "min_neighbour_separation": min(neighbours, default=math.inf),
            "pairs_inside_perimeter": sum(1 for v in every if v < perimeter),
            "neighbour_pairs_inside_perimeter": sum(1 for v in neighbours if v < perimeter)}


def run_sampled(sc, csv_path=None):
    """Run the sampled loop and print cf_sim's lines; returns an exit status."""
    runs, targets, pair_min, wall = simulate_sampled(sc)
    for i, (name, cols, xi_max) in enumerate(runs):
        if csv_path:
            path = follower_csv_path(csv_path, name) if name else csv_path
            try:
                write_csv(path, cols)
            except OSError as exc:
                print(f"{PROG}: error: cannot write {path}: {exc.strerror}", file=sys.stderr)
                return 1
        norm_xi = cols["norm_xi"]
        figures = {"max_xi": float(np.max(norm_xi)),
                   "max_xi_hat": float(np.max(cols["norm_xi_hat"])), "xi_max": xi_max,
                   "min_separation": float(np.min(cols["separation"])),
                   "time_outside": int(np.count_nonzero(norm_xi > xi_max)) / sc.control_rate,
                   "wall_s": wall}
        if sc.safety_filter is not None:
            figures["barrier_ticks"] = int(np.count_nonzero(cols["projected"]))
            figures["barrier_infeasible_ticks"] = int(
                np.count_nonzero(cols["barrier_infeasible"]))
        line = " ".join(f"{key}={value}" if isinstance(value, int) else f"{key}={value:.9g}"
                        for key, value in figures.items())
        target = "leader" if targets[i] == 0 else f"follower_{targets[i]}"
        print(f"{name} target={target} {line}" if name else line, flush=True)
    if sc.formation is not None:
        print(formation_line(sc, pair_figures(pair_min, targets, sc.perimeter), wall))
    return 0


def formation_line(sc, figures, wall):
    fm = sc.formation
    text = " ".join(f"{key}={value:.9g}" if isinstance(value, float) else f"{key}={value}"
                    for key, value in figures.items())
    return (f"formation followers={fm.followers} topology={fm.topology} shape={fm.shape} "
            f"slots={fm.slots} {text} wall_s={wall:.9g}")


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
    ap.add_argument("--sampled", action="store_true",
                    help="run the sampled loop (as with a section world or formation.neighbours)")
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


def pair_minima(runs, k):
    """(F + 1, F + 1): the smallest distance between each two agents (0 the leader, i follower
    i) on the grid."""
    points = [np.vstack([runs[0][2][f"leader_p_{i}"] for i in range(k)])]
    points += [np.vstack([cols[f"follower_p_{i}"] for i in range(k)]) for _, _, cols, _ in runs]
    out = np.full((len(points), len(points)), math.inf)
    for j in range(1, len(points)):
        for i in range(j):
            out[i, j] = out[j, i] = float(np.min(np.linalg.norm(points[j] - points[i], axis=0)))
    return out


def main(argv=None):
    args = parse_args(argv)
    try:
        sc = load_scenario(args.scenario, args.overrides, args.sampled)
    except ScenarioError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    if sc.sampled:
        return run_sampled(sc, args.csv)
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
        figures = pair_figures(pair_minima(runs, sc.k), [0] * len(runs), sc.perimeter)
        print(formation_line(sc, figures, sum(r[3] for r in runs)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
