#!/usr/bin/python3
"""Cross-check cf_sim's world (section ``world``) and neighbours (``formation.neighbours``, the
command projection (N1)-(N3) of doc/formations.md, "Neighbours") against reference_sim.py.

Usage::

    compare_neighbours.py --cf-sim PATH --scenarios-dir DIR [--xunit FILE] [--jobs N]
                          [--tolerance M] [--case NAME]... [--list] [--keep DIR]
                          [--reference PATH]

Each case (config/scenarios/crowd_v4_gust.yaml or crowd_16_gusts.yaml plus ``--set``
overrides) is run through cf_sim and through reference_sim.py, whose sampled loop (chosen by
the section world or formation.neighbours) is written from the equations: the pair's laws of
doc/math.md ("Follower command", "Discretisation", "Offline simulator"), the true vehicles,
gusts, noise and draws of doc/formations.md ("A world that can hurt") and (N1)-(N3), with the
projection solved exactly by enumerating active sets. A case passes when

  * both report the same followers with the same targets and xi_max,
  * per follower max_xi, max_xi_hat and min_separation, and the formation's
    min_pair_separation and min_neighbour_separation agree within the case's tolerance (m), and
  * both count the same pairs_inside_perimeter and neighbour_pairs_inside_perimeter.

On a failure the first tick where a follower's command u or position differs by more than the
tolerance is printed with both commands and what the reference did there (saturated,
projected, half-spaces kept and dropped): a different command with the same position before it
points at the controller or the projection of that tick.

Tolerances. Both sides run the same sampled recursion, so they differ by rounding only where
the laws are followed: the tolerance is 1e-6 m for every case. Measured (2026-12-06): every case agrees in every
compared figure to all nine printed digits, and over every tick of the CSVs to <= 5e-13 m in
position and <= 7.3e-12 m/s^2 in u, including the 16-follower runs in which the half-spaces are
infeasible at many ticks and some are dropped (the dropping rule of (N3)).

Ill-conditioning to know of: a follower far outside its bound has its estimate held on the
sphere ||xi_hat|| = xi_max, and the estimate's direction on it amplifies rounding (about tenfold
every 6 ticks in a gusted V of 16 with A_n = 3, omega = 0.5, seed 1: cf_sim and the reference
part by O(1) in xi_hat from about 16 s while positions and commands agree to 1e-11, until a tick
where a single half-space binds and the projection follows the command's direction, at 24.47 s).
The norms compared are unaffected (both on the sphere); the cases here are chosen clear of it.

Runtime: about 17 s with --jobs 2 on 2 cores, nearly all of it the reference (the two
16-follower cases, shortened to 30 s of simulated time, take about 15 s each).

One line per case, then ``N passed, M failed``; exit status 1 if any failed, 2 for a bad command
line. --xunit writes a JUnit XML file as compare_with_reference.py does. A tool path ending in
``.py`` runs with /usr/bin/python3 (passing reference_sim.py as --cf-sim checks the plumbing:
every difference is then 0).
"""

import math
import os
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_common import case_parser, run_both, run_cases  # noqa: E402  (beside this file)

HERE = Path(__file__).resolve().parent
DEFAULT_REFERENCE = HERE / "reference_sim.py"
TOLERANCE = 1e-6          # m
FOLLOWER_KEYS = ("max_xi", "max_xi_hat", "min_separation")
FORMATION_KEYS = ("min_pair_separation", "min_neighbour_separation")
COUNTS = ("pairs_inside_perimeter", "neighbour_pairs_inside_perimeter")

V4 = "crowd_v4_gust.yaml"
CROWD16 = "crowd_16_gusts.yaml"


def _neighbours(**keys):
    return "formation.neighbours={" + ", ".join(f"{k}: {v!r}" for k, v in keys.items()) + "}"


_V4_NEIGHBOURS = ("controller.acceleration_limit=3",
                  _neighbours(braking_acceleration=1, neighbour_acceleration=2, rate=1))
_CROWD16_NEIGHBOURS = ("simulation.duration=30", "controller.acceleration_limit=4",
                       _neighbours(braking_acceleration=1.5, neighbour_acceleration=2.5, rate=1))
# Noise, gusts, a lag on follower 1, and on follower 3 a sinusoid, a lag, a gain and a pulse
# whose edges fall inside control periods (the sinusoid is taken at the middle of each piece).
_NOISY_WORLD = (
    "world.seed=3",
    "world.measurement_noise={position: 0.05, velocity: 0.1}",
    "world.gusts={rate: 0.2, magnitude: 3.0}",
    "world.followers=[{index: 1, vehicle: {actuator_lag: 0.1}}, "
    "{index: 3, sinusoids: [{amplitude: [0.05, 0.0, 0.8, -0.5], frequency: 0.3, phase: 0.4}], "
    "disturbance: [{start: 10.0037, end: 12.5051, vector: [0.1, 0.0, 1.0, 2.0]}], "
    "vehicle: {actuator_lag: 0.35, input_gain: 0.9}}]",
)


@dataclass(frozen=True)
class Case:
    name: str
    scenario: str
    overrides: tuple
    note: str
    tolerance: float = TOLERANCE


CASES = (
    Case("v4_gust", V4, (),
         "V star of 4, follower 2 pushed at 5 m/s^2 into a 3 m/s^2 vehicle; no neighbours"),
    Case("v4_gust_neighbours", V4, _V4_NEIGHBOURS,
         "the same with a_max 3 and neighbours a_b 1, A_n 2, omega 1"),
    Case("crowd16_seed1_neighbours", CROWD16, _CROWD16_NEIGHBOURS + ("world.seed=1",),
         "V star of 16 in gusts, lag, noise, 30 s; a_max 4, neighbours a_b 1.5, A_n 2.5, omega 1 "
         "(infeasible sets: the dropping rule)"),
    Case("crowd16_seed2_neighbours", CROWD16, _CROWD16_NEIGHBOURS + ("world.seed=2",),
         "the same, seed 2"),
    Case("v4_noise_sinusoid_lag", V4, _NOISY_WORLD,
         "noise, gusts, lags, a gain and a sinusoid; no neighbours"),
    Case("v4_noise_sinusoid_lag_neighbours", V4, _NOISY_WORLD + (
        "controller.acceleration_limit=6",
        _neighbours(braking_acceleration=2, neighbour_acceleration=0.5, rate=1.5)),
         "the same with a_max 6 and neighbours a_b 2, A_n 0.5, omega 1.5"),
    Case("chain_v_jerk_neighbours", V4, (
        "formation.topology=chain", "controller.acceleration_limit=5", "controller.jerk_limit=40",
        _neighbours(braking_acceleration=2, neighbour_acceleration=0.5, rate=1, radius=12,
                    max_neighbours=2),
        "world.measurement_noise={position: 0.01, velocity: 0.02}"),
         "V chain of 4 (targets are followers), jerk limit, radius 12 m, 2 half-spaces kept"),
)


def parse_summaries(stdout):
    """({follower_<i>: {key: value}}, {formation key: value}) of the summary lines."""
    followers, formation = {}, {}
    for line in stdout.splitlines():
        tokens = line.split()
        if not tokens:
            continue
        pairs = dict(t.split("=", 1) for t in tokens[1:] if "=" in t)
        if tokens[0].startswith("follower_"):
            for key in FOLLOWER_KEYS + ("xi_max",):
                pairs[key] = float(pairs[key])
            followers[tokens[0]] = pairs
        elif tokens[0] == "formation":
            for key in FORMATION_KEYS:
                pairs[key] = float(pairs[key])
            for key in COUNTS:
                pairs[key] = int(pairs[key])
            formation = pairs
    if not followers:
        raise ValueError("no follower_<i> summary line on stdout")
    if not formation:
        raise ValueError("no formation summary line on stdout")
    return followers, formation


def read_csv(path):
    with open(path, encoding="utf-8") as fh:
        names = fh.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {name: data[:, i] for i, name in enumerate(names)}


def columns(cols, prefix):
    names = sorted((c for c in cols if c.startswith(prefix) and c[len(prefix):].isdigit()),
                   key=lambda c: int(c[len(prefix):]))
    return np.column_stack([cols[c] for c in names])


def difference(a, b):
    """|a - b|, 0 where both are the same infinity."""
    if a == b:
        return 0.0
    return abs(a - b) if math.isfinite(a) and math.isfinite(b) else math.inf


def csv_differences(work, names, tol):
    """(largest |u| difference (m/s^2), largest position difference (m) over every tick and
    follower, text of the earliest tick where some follower's u or position differs by more than
    tol ('' if none)), from the two tools' CSVs."""
    earliest, max_du, max_dp = None, 0.0, 0.0
    for name in names:
        try:
            cf = read_csv(work / f"cf_sim_{name}.csv")
            ref = read_csv(work / f"reference_{name}.csv")
        except (OSError, ValueError) as exc:
            return math.inf, math.inf, f"(CSV of {name}: {exc})"
        if cf["t"].size != ref["t"].size:
            return (math.inf, math.inf,
                    f"{name}: the CSVs have {cf['t'].size} and {ref['t'].size} rows")
        du = np.linalg.norm(columns(cf, "u_") - columns(ref, "u_"), axis=1)
        dp = np.linalg.norm(columns(cf, "follower_p_") - columns(ref, "follower_p_"), axis=1)
        max_du, max_dp = max(max_du, float(np.max(du))), max(max_dp, float(np.max(dp)))
        bad = np.nonzero(~((du <= tol) & (dp <= tol)))[0]
        if bad.size and (earliest is None or bad[0] < earliest[0]):
            earliest = (int(bad[0]), name, cf, ref, du, dp)
    if earliest is None:
        return max_du, max_dp, ""
    i, name, cf, ref, du, dp = earliest
    fmt = lambda v: "[" + ", ".join(f"{x:.9g}" for x in v) + "]"  # noqa: E731
    flags = " ".join(f"{key}={ref[key][i]:g}" for key in
                     ("saturated", "rate_limited", "projected", "kept", "dropped") if key in ref)
    return max_du, max_dp, (
        f"first u or p difference > {tol:g} at t={cf['t'][i]:.2f} s (tick {i}), {name}: "
        f"|du|={du[i]:.3g} |dp|={dp[i]:.3g}; u cf_sim {fmt(columns(cf, 'u_')[i])}, reference "
        f"{fmt(columns(ref, 'u_')[i])} (reference: {flags})")


def check_case(case, cf_sim, reference, scenarios_dir, tolerance=None, keep=None):
    """Run both tools on a case; return (passed, report line)."""
    tol = case.tolerance if tolerance is None else tolerance
    scenario = Path(scenarios_dir) / case.scenario
    if not scenario.is_file():
        return False, f"FAIL {case.name}: no scenario file {scenario}"
    with tempfile.TemporaryDirectory(prefix="compare_neighbours_") as tmp:
        work = Path(keep) / case.name if keep else Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        cf, ref, error = run_both(cf_sim, reference, scenario, work, case.overrides,
                                  parse_summaries)
        if error:
            return False, f"FAIL {case.name}: {error}"
        (cf_f, cf_form), (ref_f, ref_form) = cf, ref
        problems = []
        if set(cf_f) != set(ref_f):
            problems.append(f"followers differ: cf_sim {sorted(cf_f)}, reference {sorted(ref_f)}")
        worst = {key: (0.0, "") for key in FOLLOWER_KEYS}
        for name in sorted(set(cf_f) & set(ref_f), key=lambda n: int(n.split("_")[1])):
            a, b = cf_f[name], ref_f[name]
            if a.get("target") != b.get("target"):
                problems.append(f"{name}: target {a.get('target')} != {b.get('target')}")
            if not abs(a["xi_max"] - b["xi_max"]) <= 1e-9 * max(1.0, b["xi_max"]):
                problems.append(f"{name}: xi_max {a['xi_max']:.9g} != {b['xi_max']:.9g}")
            for key in FOLLOWER_KEYS:
                diff = difference(a[key], b[key])
                if diff > worst[key][0]:
                    worst[key] = (diff, name)
                if not diff <= tol:
                    problems.append(f"{name}: {key} {a[key]:.9g} / {b[key]:.9g} differs by "
                                    f"{diff:.3g} m > {tol:g}")
        parts = [f"{key}={d:.1e}" + (f" ({who})" if d > 0 else "")
                 for key, (d, who) in worst.items()]
        for key in FORMATION_KEYS:
            diff = difference(cf_form[key], ref_form[key])
            parts.append(f"{key}={diff:.1e} ({cf_form[key]:.4f})")
            if not diff <= tol:
                problems.append(f"formation: {key} {cf_form[key]:.9g} / {ref_form[key]:.9g} "
                                f"differs by {diff:.3g} m > {tol:g}")
        for key in COUNTS:
            if cf_form[key] != ref_form[key]:
                problems.append(f"formation: {key} {cf_form[key]} != {ref_form[key]}")
        names = sorted(set(cf_f) & set(ref_f), key=lambda n: int(n.split("_")[1]))
        max_du, max_dp, first = csv_differences(work, names, tol)
        parts.append(f"CSV: u={max_du:.1e} p={max_dp:.1e}")
        if problems:
            problems.append(first or "no tick differs by more than the tolerance in u or p")
    line = f"{'FAIL' if problems else 'ok  '} {case.name:<34} " + " ".join(parts)
    if problems:
        line += " -- " + "; ".join(problems)
    return not problems, line


def main(argv=None):
    args = case_parser("compare_neighbours.py", "Compare cf_sim's world and neighbours with "
                       "reference_sim.py (see the module docstring).", DEFAULT_REFERENCE
                       ).parse_args(argv)
    # The slowest first, so that two jobs finish together.
    return run_cases("compare_neighbours", CASES, args,
                     lambda c: check_case(c, args.cf_sim, args.reference, args.scenarios_dir,
                                          args.tolerance, args.keep),
                     lambda c: f"{c.name:<34} {c.scenario:<20} {c.tolerance:<6g} {c.note}", 34,
                     first=lambda c: c.scenario == CROWD16)


if __name__ == "__main__":
    sys.exit(main())
