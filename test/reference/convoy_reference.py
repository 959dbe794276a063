#!/usr/bin/python3
"""Sampled reference of convoys (``formation.slots: path``) in cf_sim, from doc/math.md.

An independent implementation of doc/math.md, "Convoys on the target's path" (C1)-(C5), with
the pair's laws of "Follower command" and "Discretisation", written from the equations (not
from core/ConvoyReference or core/TargetPath), to cross-check cf_sim (compare_convoy.py). The
scenario is read by reference_sim.py's parser; the formation section is read here.

Per control tick t_k = k T (T = 1 / control_rate), follower i, target t (the leader, or
follower i - 1 in a chain), in index order, every agent at its state of the tick:

    (C1) record p_t into the target's path; s_k its progress     (convoy_path.TargetPath)
    (C2) sigma*_k, q_k = P(sigma*_k)                              (convoy_path.Goal)
    (C3) v* = clamp_norm(q' + clamp_norm((w_r / (2 z_r)) (q - r), c), |v_t| + c),
         r''_0 = clamp_norm(2 z_r w_r (v* - r'), a_max),  q' = (q_k - q_{k-1}) / T
    (C5) c = |p_t - r|, n = (p_t - r) / c, v_r = n.r', v_t = n.v_t,
         h = c - c_min - max(v_r, 0)^2 / (2 a_b) + max(v_t, 0)^2 / (2 A),  c_min = (1 + m/2)|d_i|
         N = w_r h + min(0, v_t) - v_r, delta = max(v_r, a_b T) if N < 0 else max(v_r, a_b / w_r),
         n.r'' <= max(-a_max, a_b N / delta): where r''_0 exceeds it, its component along n is
         set to the bound (`braking`) and its part across n scaled down to keep |r''| <= a_max
    (C4) xi = [r - p_i; r' - v_i],  u_i = G y + r''  (y = xi, C = I)

then r, r' and every plant are integrated exactly over [t_k, t_k + T] with r'' and u_i held
("Discretisation"). The paper's estimator and tracker are not modelled: from xi(0) = 0, y = 0,
xi_hat = 0 and u_a = 0 (C4), so u_i = G y + r'' is their command; a difference would show in
xi. The leader is the scenario's double integrator, u_1 sampled at each tick and held, its
disturbance pulses exact (a period split at their edges; "Offline simulator (cf_sim)").

The start, which doc/math.md leaves to the layout: the path holds the target's initial
position, with the road along d_i's position part; r(0) = q_0 = P(-g), r'(0) the target's
velocity projected on that road, q_{-1} = q_0 - r'(0) T (so q'_0 = r'(0)), sigma*_{-1} =
sigma*_0, s_{-1} = s_0; follower i starts at [r(0); r'(0)] minus the scenario's relative error
x_1(0) - x_2(0) - d. A chain has d_i = d, follower i - 1 as target; a star d_i = i d.

Usage::

    convoy_reference.py SCENARIO.yaml [--set key=value]... [--csv FILE]

prints ``follower_<i> target=<name> max_xi=.. xi_max=.. min_separation=.. min_chord=..
max_path_deviation=.. braking_ticks=..`` per follower (max_path_deviation: the largest distance
of the follower from its target's path as recorded at the tick); --csv FILE writes
FILE_follower_<i>.ext per follower (t, target_*, follower_*, ref_*, goal_*, progress, goal_arc,
chord, braking). Exit codes: 0 success, 2 bad command line or scenario.
"""

import argparse
import math
import os
import sys
import time
from dataclasses import dataclass

import numpy as np
import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
# reference_sim.py's parser and signals, beside this file.
from refsim_continuous import follower_csv_path, write_csv  # noqa: E402
from refsim_format import apply_override, as_float, ScenarioError  # noqa: E402
from refsim_inputs import pulse_sum, sinusoid_sum  # noqa: E402
from refsim_scenario import build_scenario  # noqa: E402
from convoy_path import Goal, TargetPath, unit  # noqa: E402

PROG = "convoy_reference"


@dataclass(frozen=True)
class PathParameters:
    """formation.path, defaults of doc/math.md (C1)-(C5)."""

    gap_ratio: float = 1.5
    margin_ratio: float = 0.4
    spacing: float = 0.05
    capacity: int = 4096
    retrace_width: float = 0.5
    natural_frequency: float = 2.0
    damping: float = 1.0
    max_acceleration: float = 5.0
    braking_acceleration: float = 4.0
    target_braking: float = 5.0
    catch_up_speed: float = 1.0


def parse_convoy(node):
    """(followers, topology, PathParameters) of the formation section; slots must be path."""
    if not isinstance(node, dict):
        raise ScenarioError("formation: expected a mapping with slots: path")
    allowed = {"followers", "topology", "shape", "half_angle", "slots", "turning", "path"}
    for key in node:
        if key not in allowed:
            raise ScenarioError(f"unknown key 'formation.{key}'")
    if node.get("slots") != "path":
        raise ScenarioError("formation.slots: this reference covers path only")
    if node.get("shape", "line") != "line":
        raise ScenarioError("formation.shape: path slots need a line")
    followers = node.get("followers")
    if isinstance(followers, bool) or not isinstance(followers, int) or followers < 1:
        raise ScenarioError("formation.followers: expected an integer >= 1")
    topology = node.get("topology", "star")
    if topology not in ("star", "chain"):
        raise ScenarioError("formation.topology: expected star or chain")
    pnode = node.get("path") or {}
    if not isinstance(pnode, dict):
        raise ScenarioError("formation.path: expected a mapping")
    values = {}
    for key in vars(PathParameters()):
        if key not in pnode:
            continue
        if key == "capacity":
            if isinstance(pnode[key], bool) or not isinstance(pnode[key], int) or pnode[key] < 2:
                raise ScenarioError("formation.path.capacity: expected an integer >= 2")
            values[key] = pnode[key]
        else:
            values[key] = as_float(pnode[key], f"formation.path.{key}")
    for key in pnode:
        if key not in vars(PathParameters()):
            raise ScenarioError(f"unknown key 'formation.path.{key}'")
    prm = PathParameters(**values)
    if not (min(prm.spacing, prm.natural_frequency, prm.damping, prm.max_acceleration,
                prm.braking_acceleration, prm.target_braking, prm.catch_up_speed) > 0.0
            and prm.margin_ratio >= 0.0 and prm.retrace_width >= 0.0):
        raise ScenarioError("formation.path: values must be > 0 (margin_ratio, "
                               "retrace_width >= 0)")
    if prm.gap_ratio < 1.0 + prm.margin_ratio:
        raise ScenarioError("formation.path.gap_ratio: must be >= 1 + margin_ratio")
    if prm.braking_acceleration > prm.max_acceleration:
        raise ScenarioError("formation.path.braking_acceleration: exceeds max_acceleration")
    return followers, topology, prm


def load(path, overrides):
    """(Scenario of reference_sim without its formation, followers, topology, parameters)."""
    try:
        with open(path, encoding="utf-8") as fh:
            raw = yaml.safe_load(fh) or {}
    except (OSError, yaml.YAMLError) as exc:
        raise ScenarioError(f"cannot read {path}: {exc}") from None
    for assignment in overrides:
        apply_override(raw, assignment)
    formation = parse_convoy(raw.pop("formation", None))
    sc = build_scenario(raw)
    if not sc.double_integrator:
        raise ScenarioError("model.type: path slots need a double_integrator")
    if sc.info_command or sc.info_estimator:
        raise ScenarioError("controller.leader_information: must be false with path slots")
    return (sc,) + formation


def clamp_norm(v, limit):
    """v scaled down to norm limit when longer."""
    norm = math.sqrt(float(v @ v))
    return v * (limit / norm) if norm > limit else v


class ConvoyReference:
    """r, r' of one follower (C3)-(C5) on its target's path (C1), toward its goal (C2)."""

    def __init__(self, prm, period, d_norm, p0, v0, direction, max_points):
        self.prm, self.T = prm, period
        self.w, self.z = prm.natural_frequency, prm.damping
        self.c_min = (1.0 + prm.margin_ratio / 2.0) * d_norm
        self.path = TargetPath(p0, direction, prm.spacing, prm.capacity, prm.retrace_width,
                               max_points)
        self.goal = Goal(prm.gap_ratio * d_norm, (1.0 + prm.margin_ratio) * d_norm,
                         prm.catch_up_speed, period)
        sigma, q = self.goal.tick(self.path, p0)
        self.r = q.copy()
        self.rd = float(v0 @ direction) * direction
        self.q_prev = q - self.rd * period

    def tick(self, p, v):
        """One tick: returns the sample (r, r', r'', q, s, sigma*, c, braking), then moves r."""
        prm, T = self.prm, self.T
        s = self.path.record(p)
        sigma, q = self.goal.tick(self.path, p)
        qd = (q - self.q_prev) / T
        self.q_prev = q
        approach = clamp_norm(self.w / (2.0 * self.z) * (q - self.r), prm.catch_up_speed)
        speed = clamp_norm(qd + approach, math.sqrt(float(v @ v)) + prm.catch_up_speed)
        acc = clamp_norm(2.0 * self.z * self.w * (speed - self.rd), prm.max_acceleration)  # (C3)
        rel = p - self.r
        chord = math.sqrt(float(rel @ rel))
        braking = False
        n = unit(rel)
        if n is not None:                                               # (C5)
            v_r, v_t = float(n @ self.rd), float(n @ v)
            ab = prm.braking_acceleration
            h = (chord - self.c_min - max(v_r, 0.0) ** 2 / (2.0 * ab)
                 + max(v_t, 0.0) ** 2 / (2.0 * prm.target_braking))
            numerator = self.w * h + min(0.0, v_t) - v_r
            delta = max(v_r, ab * T if numerator < 0.0 else ab / self.w)
            bound = max(-prm.max_acceleration, ab * numerator / delta)
            along = float(n @ acc)
            if along > bound:
                across = clamp_norm(acc - along * n,
                                    math.sqrt(max(0.0, prm.max_acceleration ** 2 - bound ** 2)))
                acc = bound * n + across
                braking = True
        sample = (self.r.copy(), self.rd.copy(), acc, q, s, sigma, chord, braking)
        self.r = self.r + self.rd * T + 0.5 * T * T * acc
        self.rd = self.rd + T * acc
        return sample


def advance_leader(sc, x, t, u1, T):
    """The leader over [t, t + T]: u1 held, the disturbance pulses exact (split at edges)."""
    k = sc.k
    cuts = sorted({t, t + T} | {e for a, b, _ in sc.disturbances for e in (a, b)
                                if t < e < t + T})
    x = x.copy()
    for a, b in zip(cuts[:-1], cuts[1:]):
        ud = pulse_sum(sc.disturbances, 0.5 * (a + b), sc.n)[:, 0]
        dt, acc = b - a, u1 + ud[k:]
        x[:k] = x[:k] + x[k:] * dt + 0.5 * dt * dt * acc + ud[:k] * dt
        x[k:] = x[k:] + acc * dt
    return x


def simulate(sc, followers, topology, prm):
    """Run the convoy; returns per follower (name, target name, d_i, columns dict)."""
    k, T = sc.k, 1.0 / sc.control_rate
    ticks = int(round(sc.duration * sc.control_rate))
    chain = topology == "chain"
    error0 = sc.x1_0 - sc.x2_0 - sc.d
    states, refs, seps = [], [], []
    for i in range(1, followers + 1):
        d_i = sc.d if chain else i * sc.d
        target = states[i - 2] if chain and i > 1 else sc.x1_0
        direction = unit(d_i[:k])
        ref = ConvoyReference(prm, T, float(np.linalg.norm(d_i[:k])), target[:k].copy(),
                              target[k:].copy(), direction, ticks + 1)
        states.append(np.concatenate([ref.r, ref.rd]) - error0)
        refs.append(ref)
        seps.append(d_i)
    leader = sc.x1_0.copy()
    rows = [[] for _ in range(followers)]
    grid = np.arange(ticks + 1) / sc.control_rate
    inputs = pulse_sum(sc.input_pulses, grid, sc.m) + sinusoid_sum(sc.sinusoids, grid, sc.m)
    for tick in range(ticks + 1):
        t, u1 = grid[tick], inputs[:, tick]
        commands = []
        for i, ref in enumerate(refs):
            target = states[i - 1] if chain and i > 0 else leader
            x = states[i]
            r, rd, acc, q, s, sigma, chord, braking = ref.tick(target[:k], target[k:])
            xi = np.concatenate([r - x[:k], rd - x[k:]])                # (C4)
            commands.append(sc.G @ xi + acc)
            deviation = ref.path.distance(x[:k])
            rows[i].append(np.concatenate([[t], target, x, r, rd, acc, q,
                                           [s, sigma, chord, float(braking),
                                            np.linalg.norm(target[:k] - x[:k]),
                                            np.linalg.norm(xi), deviation]]))
        if tick < ticks:
            leader = advance_leader(sc, leader, t, u1, T)
            for i, u in enumerate(commands):
                x = states[i]
                states[i] = np.concatenate([x[:k] + x[k:] * T + 0.5 * T * T * u, x[k:] + u * T])
    names = ([f"target_p_{j}" for j in range(k)] + [f"target_v_{j}" for j in range(k)]
             + [f"follower_p_{j}" for j in range(k)] + [f"follower_v_{j}" for j in range(k)]
             + [f"ref_p_{j}" for j in range(k)] + [f"ref_v_{j}" for j in range(k)]
             + [f"u_slot_{j}" for j in range(k)] + [f"goal_p_{j}" for j in range(k)]
             + ["progress", "goal_arc", "chord", "braking", "separation", "norm_xi",
                "path_deviation"])
    out = []
    for i in range(followers):
        data = np.array(rows[i])
        cols = {"t": data[:, 0]}
        cols.update({name: data[:, j + 1] for j, name in enumerate(names)})
        target = "leader" if i == 0 or not chain else f"follower_{i}"
        out.append((f"follower_{i + 1}", target, seps[i], cols))
    return out


def summary(sc, d_i, cols, wall):
    xi_max = (1.0 - sc.alpha) * float(np.linalg.norm(d_i))
    return {"max_xi": float(np.max(cols["norm_xi"])), "xi_max": xi_max,
            "min_separation": float(np.min(cols["separation"])),
            "min_chord": float(np.min(cols["chord"])),
            "max_path_deviation": float(np.max(cols["path_deviation"])),
            "braking_ticks": int(np.sum(cols["braking"])), "wall_s": wall}


def main(argv=None):
    ap = argparse.ArgumentParser(prog="convoy_reference.py",
                                 description="Sampled reference of cf_sim's path slots "
                                             "(doc/math.md (C1)-(C5)); see the module docstring.")
    ap.add_argument("scenario")
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--csv", metavar="FILE", help="write FILE_follower_<i>.ext per follower")
    args = ap.parse_args(argv)
    try:
        sc, followers, topology, prm = load(args.scenario, args.overrides)
    except ScenarioError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    wall0 = time.perf_counter()
    runs = simulate(sc, followers, topology, prm)
    wall = time.perf_counter() - wall0
    for name, target, d_i, cols in runs:
        if args.csv:
            write_csv(follower_csv_path(args.csv, name), cols)
        line = " ".join(f"{key}={value:.9g}" for key, value in
                        summary(sc, d_i, cols, wall).items())
        print(f"{name} target={target} {line}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
