#!/usr/bin/python3
"""Cross-check cf_sim's convoys (``formation.slots: path``) against convoy_reference.py.

Usage::

    compare_convoy.py --cf-sim PATH --scenarios-dir DIR [--xunit FILE] [--jobs N]
                      [--case NAME]... [--list] [--keep DIR] [--reference PATH]

Each case (a scenario plus ``--set`` overrides, ``formation.slots=path`` always) is run through
cf_sim and through the independent reference of doc/math.md (C1)-(C5) (convoy_reference.py),
both writing per-follower CSVs. Per follower a case passes when

  * both report the same followers and targets and the same xi_max,
  * the reference point r (``ref_p_*``) and the follower's position (``follower_p_*``) agree at
    every tick within the case's tolerance (max over ticks of the distance),
  * min_separation (the summary's, the distance to the target) and the smallest chord c of (C5)
    (min of the CSV's ``chord``) agree within it, and
  * cf_sim's follower stays on its reference: max_xi <= 1e-9 m ((C4): from xi(0) = 0, xi stays 0).

On a failure the first tick where the goal q (C1)/(C2) or r'' (C3)/(C5) of the two differs by
more than the tolerance is printed with both values: a different q points at the path or the
goal, the same q with a different r'' at the pull or the barrier.

Tolerances. Both sides run the same sampled recursion (doc/math.md, "Discretisation"), so a
cf_sim that follows (C1)-(C5) differs by rounding only. The tolerance is 1e-6 m for every case
(r, p, min_separation, min chord), four orders above the rounding measured below and far below
any change of law (the smallest departure seen, 2e-3 m/s^2 in r'', moved r by 1e-7 m the next
tick and by metres within seconds). A threshold of (C1) decided differently through rounding (a
point added at exactly `spacing`, a retrace at exactly 0) would show as an isolated larger
difference; none was seen.

Measured (2026-12-06, runtime 10 s with --jobs 2 on 2 cores): every case passes; the largest
difference over all ticks and followers is 1.6e-10 m in r and p (pair_figure_eight, 12,001
ticks; <= 6e-11 m elsewhere), min_separation agrees to all printed digits and the smallest chord
within 3e-12 m. Before (C3) took its speed form and (C5) its divisor delta, the same comparison
against the earlier laws failed every case by metres from the first tick where r'' differed: a
change of law does not hide under the tolerance.

One line per case, then ``N passed, M failed``; exit status 1 if any failed, 2 for a bad command
line. --xunit writes a JUnit XML file as compare_with_reference.py does. A tool path ending in
``.py`` runs with /usr/bin/python3 (passing convoy_reference.py as --cf-sim checks the plumbing:
every difference is then 0).
"""

import os
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_common import case_parser, run_both, run_cases  # noqa: E402  (beside this file)

HERE = Path(__file__).resolve().parent
DEFAULT_REFERENCE = HERE / "convoy_reference.py"
TOLERANCE = 1e-6          # m
XI_SLACK = 1e-9           # m: cf_sim's follower on its reference, (C4)

PATH_SLOTS = ("formation.slots=path",)


def _chain(n):
    return PATH_SLOTS + (f"formation.followers={n}", "formation.topology=chain")


def _pair(*extra):
    return PATH_SLOTS + ("formation.followers=1",) + extra


@dataclass(frozen=True)
class Case:
    name: str
    scenario: str
    overrides: tuple
    note: str
    tolerance: float = TOLERANCE


CASES = (
    Case("pair_circle", "turning_circle.yaml", _pair(),
         "circle of 10 m at 2 m/s, pushed along its heading"),
    Case("pair_u_turn", "turning_u_turn.yaml", _pair(),
         "U-turn of 5 m, then pushed back over its path (retrace)"),
    Case("pair_stop_and_go", "turning_stop_and_go.yaml", _pair(),
         "stops, starts, turns, is pushed into reverse at 4 m/s"),
    Case("pair_figure_eight", "figure_eight_2d.yaml", _pair(),
         "leader at 45 deg to d: the road stays along d, the path turns at its start"),
    Case("chain3_u_turn", "turning_u_turn.yaml", _chain(3), "chain of 3 on the U-turn"),
    Case("chain3_stop_and_go", "turning_stop_and_go.yaml", _chain(3),
         "chain of 3 on the stop-and-go"),
    Case("laws_stop_and_go", "turning_stop_and_go.yaml",
         _pair("formation.path={gap_ratio: 2.0, margin_ratio: 0.6, natural_frequency: 1.5, "
               "damping: 0.8, max_acceleration: 4.0, braking_acceleration: 3.0, "
               "target_braking: 4.0, catch_up_speed: 1.5}"),
         "other gap, margin, pull, a_max, a_b, A and catch-up speed"),
    Case("fast_u_turn_short_ring", "turning_u_turn.yaml",
         _pair("leader.initial_state=[0.0, 0.0, 3.0, 0.0]",
               "follower.initial_state=[-5.0, 0.0, 3.0, 0.0]",
               "formation.path={capacity: 50, spacing: 0.1, retrace_width: 0.3}"),
         "leader at 3 m/s (a wider turn of 120 deg); a ring of 50 points 0.1 m apart, shorter "
         "than the gap: the goal runs on the virtual road beyond the oldest point"),
    Case("line_1d_reversing", "paper_run2.yaml",
         _pair("controller.control_rate=100.0", "simulation.duration=30.0"),
         "1-D, leader at rest pushed back toward its follower: over the virtual road"),
    Case("figure_eight_3d", "figure_eight_3d.yaml", _pair("simulation.duration=40.0"),
         "3-D figure eight, 40 s"),
)


def parse_summaries(stdout):
    """{follower_<i>: {key: value}} of the ``follower_<i> target=..`` lines."""
    out = {}
    for line in stdout.splitlines():
        tokens = line.split()
        if tokens and tokens[0].startswith("follower_"):
            pairs = dict(t.split("=", 1) for t in tokens[1:] if "=" in t)
            for key in ("max_xi", "xi_max", "min_separation"):
                pairs[key] = float(pairs[key])
            out[tokens[0]] = pairs
    if not out:
        raise ValueError("no follower_<i> summary line on stdout")
    return out


def read_csv(path):
    with open(path, encoding="utf-8") as fh:
        names = fh.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {name: data[:, i] for i, name in enumerate(names)}


def columns(cols, prefix):
    names = sorted((c for c in cols if c.startswith(prefix) and c[len(prefix):].isdigit()),
                   key=lambda c: int(c[len(prefix):]))
    return np.column_stack([cols[c] for c in names])


def first_divergence(cf, ref, tol):
    """Text of the first tick where q or r'' differs by more than tol, or ''."""
    dq = np.linalg.norm(columns(cf, "goal_p_") - columns(ref, "goal_p_"), axis=1)
    du = np.linalg.norm(columns(cf, "u_slot_") - columns(ref, "u_slot_"), axis=1)
    bad = np.nonzero((dq > tol) | (du > tol))[0]
    if not bad.size:
        return ""
    i = int(bad[0])
    law = "q (C1)/(C2)" if dq[i] > tol else "r'' (C3)/(C5)"

    def at(cols):
        fmt = lambda v: "[" + ", ".join(f"{x:.9g}" for x in v) + "]"  # noqa: E731
        return (f"r={fmt(columns(cols, 'ref_p_')[i])} q={fmt(columns(cols, 'goal_p_')[i])} "
                f"r''={fmt(columns(cols, 'u_slot_')[i])} braking={cols['braking'][i]:g} "
                f"chord={cols['chord'][i]:.9g}")
    return f"first {law} difference at t={cf['t'][i]:.2f} s: cf_sim {at(cf)}; reference {at(ref)}"


def compare_follower(name, cf_sum, ref_sum, cf, ref, tol, parts, problems):
    if cf["t"].size != ref["t"].size or np.max(np.abs(cf["t"] - ref["t"])) > 1e-9:
        problems.append(f"{name}: the two CSVs have different times")
        return
    diffs = {
        "r": float(np.max(np.linalg.norm(columns(cf, "ref_p_") - columns(ref, "ref_p_"), axis=1))),
        "p": float(np.max(np.linalg.norm(columns(cf, "follower_p_")
                                         - columns(ref, "follower_p_"), axis=1))),
        "min_sep": abs(cf_sum["min_separation"] - ref_sum["min_separation"]),
        "min_chord": abs(float(np.min(cf["chord"])) - float(np.min(ref["chord"]))),
    }
    parts.append(f"{name}: " + " ".join(f"{k}={v:.1e}" for k, v in diffs.items())
                 + f" (min_sep {cf_sum['min_separation']:.4f}/{ref_sum['min_separation']:.4f})")
    over = [f"{k} {v:.3g}" for k, v in diffs.items() if not v <= tol]
    if over:
        problems.append(f"{name}: {', '.join(over)} m > {tol:g}; " + first_divergence(cf, ref, tol))
    if cf_sum.get("target") != ref_sum.get("target"):
        problems.append(f"{name}: target {cf_sum.get('target')} != {ref_sum.get('target')}")
    if not abs(cf_sum["xi_max"] - ref_sum["xi_max"]) <= 1e-9 * max(1.0, ref_sum["xi_max"]):
        problems.append(f"{name}: xi_max {cf_sum['xi_max']:.9g} != {ref_sum['xi_max']:.9g}")
    if not cf_sum["max_xi"] <= XI_SLACK:
        problems.append(f"{name}: cf_sim max_xi {cf_sum['max_xi']:.3g} m: off its reference")


def check_case(case, cf_sim, reference, scenarios_dir, keep=None):
    """Run both tools on a case; return (passed, report line)."""
    scenario = Path(scenarios_dir) / case.scenario
    if not scenario.is_file():
        return False, f"FAIL {case.name}: no scenario file {scenario}"
    with tempfile.TemporaryDirectory(prefix="compare_convoy_") as tmp:
        work = Path(keep) / case.name if keep else Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        cf, ref, error = run_both(cf_sim, reference, scenario, work, case.overrides,
                                  parse_summaries)
        if error:
            return False, f"FAIL {case.name}: {error}"
        parts, problems = [], []
        if set(cf) != set(ref):
            problems.append(f"followers differ: cf_sim {sorted(cf)}, reference {sorted(ref)}")
        for name in sorted(set(cf) & set(ref), key=lambda n: int(n.split("_")[1])):
            try:
                cf_cols = read_csv(work / f"cf_sim_{name}.csv")
                ref_cols = read_csv(work / f"reference_{name}.csv")
            except (OSError, ValueError) as exc:
                problems.append(f"{name}: {exc}")
                continue
            compare_follower(name, cf[name], ref[name], cf_cols, ref_cols, case.tolerance,
                             parts, problems)
    line = f"{'FAIL' if problems else 'ok  '} {case.name:<24} " + "; ".join(parts)
    if problems:
        line += " -- " + "; ".join(problems)
    return not problems, line


def main(argv=None):
    args = case_parser("compare_convoy.py", "Compare cf_sim's path slots with "
                       "convoy_reference.py (see the module docstring).", DEFAULT_REFERENCE,
                       tolerance=False).parse_args(argv)
    return run_cases("compare_convoy", CASES, args,
                     lambda c: check_case(c, args.cf_sim, args.reference, args.scenarios_dir,
                                          args.keep),
                     lambda c: f"{c.name:<24} {c.scenario:<26} {c.tolerance:<6g} {c.note}", 24)


if __name__ == "__main__":
    sys.exit(main())
