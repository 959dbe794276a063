#!/usr/bin/python3
"""Cross-check cf_sim's control barrier function filter (``controller.safety_filter``,
doc/math.md (B1)-(B3)) against reference_sim.py's sampled loop with barrier_reference.py.

Usage::

    compare_barrier_filter.py --cf-sim PATH --scenarios-dir DIR [--xunit FILE] [--jobs N]
                              [--tolerance M] [--case NAME]... [--list] [--keep DIR]
                              [--reference PATH]

Each case (a scenario of config/scenarios plus ``--set`` overrides, the tracker off and the
filter on) is run through cf_sim and through reference_sim.py, whose filter is written from the
equations: the barrier (B1), its half-space (B2), the QP (B3) solved exactly by enumerating
active sets, the infeasible case's best effort and the order of the barriers (the target's, then
the neighbours (N3)'s sensing keeps). A case passes when

  * both report the same followers (or the pair) with the same targets,
  * max_xi, max_xi_hat and min_separation agree within the tolerance (m), and the formation's
    min_pair_separation too,
  * barrier_ticks (ticks the filter moved the command) and barrier_infeasible_ticks are equal,
  * over every tick of the CSVs, each follower's command u and position differ by at most the
    tolerance (m/s^2, m).

On a failure the first tick where u or the position differs is printed. Tolerance 1e-6 for
every case: both sides run the same sampled recursion and differ by rounding only.
Measured (2026-12-07): every figure agrees to the nine printed digits, every count is equal
(see doc/testing.md for the largest CSV differences).

One line per case, then ``N passed, M failed``; exit status 1 if any failed, 2 for a bad command
line. --xunit writes a JUnit XML file. Runtime about 20 s with --jobs 2 on 2 cores.
"""

import os
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_common import case_parser, run_both, run_cases  # noqa: E402  (beside this file)
from compare_neighbours import columns, difference, read_csv  # noqa: E402

HERE = Path(__file__).resolve().parent
DEFAULT_REFERENCE = HERE / "reference_sim.py"
TOLERANCE = 1e-6
FIGURES = ("max_xi", "max_xi_hat", "min_separation")
COUNTS = ("barrier_ticks", "barrier_infeasible_ticks")
PAIR = "pair"

FILTER_OFF_TRACKER = ("controller.tracker.enabled=false",)


def _filter(rate):
    return FILTER_OFF_TRACKER + (f"controller.safety_filter={{rate: {rate}}}",)


def _neighbours(**keys):
    return "formation.neighbours={" + ", ".join(f"{k}: {v!r}" for k, v in keys.items()) + "}"


_SHARED = "controller.leader_information={estimator: true, disturbance: true}"
_SHORT = "simulation.duration=30"


@dataclass(frozen=True)
class Case:
    name: str
    scenario: str
    overrides: tuple
    note: str


CASES = (
    Case("run1_rate1", "paper_run1.yaml", _filter(1) + (_SHORT,),
         "the paper's Run 1, lambda 1"),
    Case("run1_rate4", "paper_run1.yaml", _filter(4) + (_SHORT,),
         "the paper's Run 1, lambda 4"),
    Case("run2_rate2", "paper_run2.yaml", _filter(2) + (_SHORT,),
         "the paper's Run 2, lambda 2"),
    Case("run2_rate4_limit", "paper_run2.yaml", _filter(4) + (
        _SHORT, "controller.acceleration_limit=0.5"),
         "Run 2, lambda 4, a_max 0.5 (infeasible ticks: the best effort)"),
    Case("velocity_push_shared", "paper_run2.yaml", _filter(2) + (
        _SHORT, _SHARED, "controller.acceleration_limit=6",
        "leader.disturbance=[{start: 20.0, end: 23.0, vector: [0.0, -8.0]}]"),
         "a velocity push of 8 m/s^2 on the leader, its acceleration shared, a_max 6"),
    Case("pair_2d_push", "vehicles_2d.yaml", _filter(3) + (
        "simulation.duration=40", _SHARED, "controller.acceleration_limit=4",
        "leader.disturbance=[{start: 20.0, end: 23.0, vector: [0.0, 0.0, -5.0, 2.0]}]"),
         "2-D pair on a curve, an oblique velocity push shared, lambda 3, a_max 4"),
    Case("pair_3d_push", "paper_run2.yaml", _filter(2.5) + (
        "model.dimension=3", "controller.separation=[5, 0, 0, 0, 0, 0]",
        "leader.initial_state=[5, 0, 0, 0, 0, 0]", "follower.initial_state=[0, 1, 0, 0, 0, 0]",
        "controller.tracker.gain=[[10, 0, 0, 5, 0, 0], [0, 10, 0, 0, 5, 0], [0, 0, 10, 0, 0, 5]]",
        "controller.tracker.reference_gain=0", "controller.control_rate=200",
        "simulation.duration=25", "controller.acceleration_limit=5",
        "controller.leader_information={command: true}",
        "leader.disturbance=[{start: 10, end: 12, vector: [0, 0, 0, -6, 1, 2]}]"),
         "3-D pair at 200 Hz, a velocity push out of the line, u_1 in the command, lambda 2.5"),
    Case("line_star_world", "crowd_v4_gust.yaml", _filter(3) + (
        "simulation.duration=30", "formation.shape=line", "formation.followers=3",
        "world.seed=3", "world.measurement_noise={position: 0.05, velocity: 0.1}",
        "world.gusts={rate: 0.3, magnitude: 4.0}",
        "world.followers=[{index: 1, vehicle: {actuator_lag: 0.1}}]",
        "controller.leader_information={command: true, disturbance: true}"),
         "line star of 3 in gusts, noise and a lag, a_1 shared, no neighbours"),
    Case("v4_gust_neighbours", "crowd_v4_gust.yaml", _filter(2) + (
        "simulation.duration=40", "controller.acceleration_limit=3",
        _neighbours(braking_acceleration=1, neighbour_acceleration=2, rate=1)),
         "V star of 4 in a gust, a barrier per kept neighbour at A_n 2 (infeasible ticks)"),
    Case("chain_v_neighbours", "crowd_v4_gust.yaml", _filter(1.5) + (
        "simulation.duration=40", "formation.topology=chain", "controller.acceleration_limit=5",
        "controller.jerk_limit=40",
        _neighbours(braking_acceleration=2, neighbour_acceleration=0.5, rate=1, radius=12,
                    max_neighbours=2)),
         "V chain of 4 (targets are followers), jerk limit, radius 12 m, 2 agents kept"),
)


def parse_summaries(stdout):
    """{follower_<i> or 'pair': {key: value}}, with the formation line's min_pair_separation
    under 'formation' when there is one."""
    out = {}
    for line in stdout.splitlines():
        tokens = line.split()
        if not tokens:
            continue
        if tokens[0].startswith("max_xi="):
            name, tokens = PAIR, ["pair"] + tokens
        else:
            name = tokens[0]
        pairs = dict(t.split("=", 1) for t in tokens[1:] if "=" in t)
        if name.startswith("follower_") or name == PAIR:
            for key in FIGURES:
                pairs[key] = float(pairs[key])
            for key in COUNTS:
                pairs[key] = int(pairs[key])
            out[name] = pairs
        elif name == "formation":
            out[name] = {"min_pair_separation": float(pairs["min_pair_separation"])}
    if not any(key != "formation" for key in out):
        raise ValueError("no summary line on stdout")
    return out


def csv_differences(work, names, tol):
    """(largest |u| difference, largest position difference, text of the earliest tick where
    either exceeds tol ('' if none)) over every tick of the two tools' CSVs."""
    max_du, max_dp, earliest = 0.0, 0.0, None
    for name in names:
        suffix = "" if name == PAIR else f"_{name}"
        try:
            cf = read_csv(work / f"cf_sim{suffix}.csv")
            ref = read_csv(work / f"reference{suffix}.csv")
        except (OSError, ValueError) as exc:
            return float("inf"), float("inf"), f"(CSV of {name}: {exc})"
        if cf["t"].size != ref["t"].size:
            return float("inf"), float("inf"), f"{name}: {cf['t'].size} != {ref['t'].size} rows"
        du = np.linalg.norm(columns(cf, "u_") - columns(ref, "u_"), axis=1)
        dp = np.linalg.norm(columns(cf, "follower_p_") - columns(ref, "follower_p_"), axis=1)
        max_du, max_dp = max(max_du, float(np.max(du))), max(max_dp, float(np.max(dp)))
        bad = np.nonzero(~((du <= tol) & (dp <= tol)))[0]
        if bad.size and (earliest is None or bad[0] < earliest[0]):
            i = int(bad[0])
            infeasible = ref["barrier_infeasible"][i] if "barrier_infeasible" in ref else 0
            earliest = (i, f"first u or p difference > {tol:g} at t={cf['t'][i]:.3f} s, {name}: "
                           f"|du|={du[i]:.3g} |dp|={dp[i]:.3g}, reference projected="
                           f"{ref['projected'][i]:g} infeasible={infeasible:g}")
    return max_du, max_dp, earliest[1] if earliest else ""


def check_case(case, cf_sim, reference, scenarios_dir, tolerance=None, keep=None):
    """Run both tools on a case; return (passed, report line)."""
    tol = TOLERANCE if tolerance is None else tolerance
    scenario = Path(scenarios_dir) / case.scenario
    if not scenario.is_file():
        return False, f"FAIL {case.name}: no scenario file {scenario}"
    with tempfile.TemporaryDirectory(prefix="compare_barrier_") as tmp:
        work = Path(keep) / case.name if keep else Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        cf, ref, error = run_both(cf_sim, reference, scenario, work, case.overrides,
                                  parse_summaries)
        if error:
            return False, f"FAIL {case.name}: {error}"
        problems, worst, counts = [], 0.0, []
        if set(cf) != set(ref):
            problems.append(f"lines differ: cf_sim {sorted(cf)}, reference {sorted(ref)}")
        names = sorted(set(cf) & set(ref) - {"formation"})
        for name in names:
            a, b = cf[name], ref[name]
            if a.get("target") != b.get("target"):
                problems.append(f"{name}: target {a.get('target')} != {b.get('target')}")
            for key in FIGURES:
                diff = difference(a[key], b[key])
                worst = max(worst, diff)
                if not diff <= tol:
                    problems.append(f"{name}: {key} {a[key]:.9g} / {b[key]:.9g}")
            for key in COUNTS:
                if a[key] != b[key]:
                    problems.append(f"{name}: {key} {a[key]} != {b[key]}")
            counts.append(f"{a['barrier_ticks']}/{a['barrier_infeasible_ticks']}")
        if "formation" in cf and "formation" in ref:
            diff = difference(cf["formation"]["min_pair_separation"],
                              ref["formation"]["min_pair_separation"])
            worst = max(worst, diff)
            if not diff <= tol:
                problems.append(f"formation: min_pair_separation differs by {diff:.3g}")
        max_du, max_dp, first = csv_differences(work, names, tol)
        if not (max_du <= tol and max_dp <= tol):
            problems.append(first)
    line = (f"{'FAIL' if problems else 'ok  '} {case.name:<22} figures {worst:.1e} "
            f"CSV u={max_du:.1e} p={max_dp:.1e} barrier/infeasible ticks {' '.join(counts)}")
    if problems:
        line += " -- " + "; ".join(problems)
    return not problems, line


def main(argv=None):
    args = case_parser("compare_barrier_filter.py", "Compare cf_sim's barrier filter with "
                       "reference_sim.py (see the module docstring).", DEFAULT_REFERENCE
                       ).parse_args(argv)
    return run_cases("compare_barrier_filter", CASES, args,
                     lambda c: check_case(c, args.cf_sim, args.reference, args.scenarios_dir,
                                          args.tolerance, args.keep),
                     lambda c: f"{c.name:<22} {c.scenario:<20} {c.note}", 22)


if __name__ == "__main__":
    sys.exit(main())
