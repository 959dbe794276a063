"""The parts of a scenario reference_sim.py parses apart: gains, pulses, the formation, the
neighbours and the section world."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import solve_continuous_lyapunov

from refsim_format import (as_axis_values, as_bool, as_float, as_matrix, as_vector, get, is_number,
                           ScenarioError)


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


def parse_gain(node, path, m, p, k, double_integrator, c_is_identity):
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


def parse_pulses(items, path, size):
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
    if not is_number(v) or math.isnan(float(v)) or not float(v) > 0.0:
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
    if not is_number(radius) or math.isnan(float(radius)) or not float(radius) >= 0.0:
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
            index=index,
            disturbances=parse_pulses(item.get("disturbance"), f"{path}.disturbance", n),
            sinusoids=sins, vehicle=_vehicle(item.get("vehicle"), f"{path}.vehicle", vehicle))
    gnode = _mapping(node.get("gusts"), "world.gusts")
    g = {}
    for key, default in vars(Gusts()).items():
        value = gnode.get(key, default)
        if key == "end":
            if not is_number(value) or math.isnan(float(value)):
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
