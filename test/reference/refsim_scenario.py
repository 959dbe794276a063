"""reference_sim.py's parsed scenario (Scenario, with the controller's derived matrices) and
its validation from the YAML tree (build_scenario, load_scenario)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
import yaml

import barrier_reference
from refsim_format import (apply_override, as_bool, as_float, as_matrix, as_vector, check_keys,
                           get, is_hurwitz, is_number, ScenarioError, SCHEMA)
from refsim_parts import (as_limit, Formation, lyapunov_gamma, parse_formation, parse_gain,
                          parse_pulses, parse_world, World)


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
    elif is_number(C_raw):
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

    G = parse_gain(get(ctl, "baseline", "controller"), "controller.baseline",
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
    Ge = parse_gain(trk, "controller.tracker", m, p, k, double_integrator, c_is_identity)
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
    input_pulses = parse_pulses(inp.get("pulses"), "leader.input.pulses", m)
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
    disturbances = parse_pulses(leader.get("disturbance"), "leader.disturbance", n)

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
