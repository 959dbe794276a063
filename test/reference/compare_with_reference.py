#!/usr/bin/python3
"""Cross-check the sampled C++ simulator cf_sim against the continuous reference.

Usage::

    compare_with_reference.py --cf-sim PATH_TO_CF_SIM --scenarios-dir config/scenarios
                              [--tolerance 0.02] [--reference test/reference/reference_sim.py]
                              [--case NAME]... [--jobs N] [--list]
                              [--cf-sim-arg=ARG]... [--reference-arg=ARG]...

For every case (a scenario file plus ``--set`` overrides) both tools are run
with the same overrides:

    cf_sim SCENARIO.yaml --set k=v ...
    reference_sim.py SCENARIO.yaml --set k=v ...

Both print one summary line of key=value pairs. A case passes when

  * |max_xi|, |max_xi_hat| and |min_separation| of the two agree within
    --tolerance (m),
  * both report the same xi_max (1e-9 relative: both read the same file), and
  * cf_sim keeps its estimate in the hard bound: max_xi_hat <= xi_max + 1e-9.

One line is printed per case, then ``N passed, M failed``; the exit status is
1 if any case failed (2 for a bad command line). A tool whose path ends in
``.py`` is run with /usr/bin/python3, so the plumbing can be tested by passing
the reference itself as --cf-sim; give it tight tolerances then
(``--cf-sim-arg=--rtol=1e-9 --cf-sim-arg=--atol=1e-12``), since at its default
tolerances the reference's own ||xi_hat|| may exceed xi_max by ~1e-6 through
integration error, which the bound check rightly reports.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import math
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

PYTHON = "/usr/bin/python3"
HERE = Path(__file__).resolve().parent
DEFAULT_REFERENCE = HERE / "reference_sim.py"
COMPARED = ("max_xi", "max_xi_hat", "min_separation")
REQUIRED = COMPARED + ("xi_max",)
BOUND_SLACK = 1e-9        # m: cf_sim's estimate must stay in ||xi_hat|| <= xi_max + this
TIMEOUT_S = 900


@dataclass(frozen=True)
class Case:
    name: str
    scenario: str             # file name inside --scenarios-dir
    overrides: tuple = ()     # "dotted.key=YAML value" strings, passed as --set
    note: str = ""


def _rotated_2d(angle_deg):
    """Overrides that turn a 1-D paper run into a 2-D one rotated by angle_deg.

    Every vector of the scenario (separation, initial states, the disturbance)
    is rotated; the gains act per axis, so the norms must equal the 1-D run's.
    """
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))

    def vec(pos, vel):            # [p_x, p_y, v_x, v_y] from 1-D magnitudes
        return f"[{pos * c:.17g}, {pos * s:.17g}, {vel * c:.17g}, {vel * s:.17g}]"

    return (
        "model.dimension=2",
        f"controller.separation={vec(5.0, 0.0)}",
        f"leader.initial_state={vec(5.0, 0.0)}",
        "follower.initial_state=[0.0, 0.0, 0.0, 0.0]",
        f"leader.disturbance.0.vector={vec(-2.0, -2.0)}",
        "controller.tracker.gain=[[10.0, 0.0, 5.0, 0.0], [0.0, 10.0, 0.0, 5.0]]",
        "controller.tracker.reference_gain=[[0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]]",
    )


_LEADER_INPUT = ("leader.input={pulses: [{start: 5.0, end: 9.0, vector: [0.8]}], "
                 "sinusoids: [{amplitude: [0.6], frequency: 0.05, phase: 0.5}]}")

def _sharing(command=False, estimator=False, disturbance=False):
    """Override setting the whole controller.leader_information mapping."""
    def yaml_bool(flag):
        return "true" if flag else "false"
    return (f"controller.leader_information={{command: {yaml_bool(command)}, "
            f"estimator: {yaml_bool(estimator)}, disturbance: {yaml_bool(disturbance)}}}")


# The overrides set whole mappings and spell matrices out in full, so that
# they do not depend on how a tool treats a --set below a key that the file
# lacks, or a plain number for a non-square matrix.
CASES = (
    Case("paper_run1", "paper_run1.yaml", note="tracker off, leaves the bound"),
    Case("paper_run2", "paper_run2.yaml", note="tracker on"),
    Case("alpha_epsilon", "paper_run1.yaml",
         ("controller.alpha=0.35", "controller.epsilon=0.05"),
         note="tighter perimeter, thin soft band"),
    Case("gains", "paper_run2.yaml",
         ("controller.baseline.natural_frequency=1.4", "controller.baseline.damping=0.9",
          "controller.tracker.gain=[[6.0, 3.0]]"),
         note="other baseline and tracker gains"),
    Case("disturbance", "paper_run2.yaml",
         ("leader.disturbance.0.vector=[1.5, 2.5]", "leader.disturbance.0.start=10.0",
          "leader.disturbance.0.end=14.5"),
         note="larger pulse pushing the leader away"),
    Case("estimator", "paper_run1.yaml",
         ("controller.estimator.gain=[[-8.0, 0.0], [0.0, -3.0]]",
          "controller.estimator.lyapunov_weight=[[4.0, 1.0], [1.0, 0.5]]",
          "controller.estimator.initial_estimate=zero", "follower.initial_state=[2.0, -1.0]"),
         note="other L and Q (Gamma far from c*I), zero initial estimate off the slot"),
    Case("tracker_off", "paper_run2.yaml",
         ("controller.tracker.enabled=false", "controller.alpha=0.1"),
         note="run 2 with the tracker switched off"),
    Case("tracker_on_big_pulse", "paper_run1.yaml",
         ("controller.tracker.enabled=true",
          "leader.disturbance.0.vector=[-3.0, -3.5]"),
         note="tracker on, beyond the paper's safe disturbance size"),
    Case("leader_input_shared", "paper_run2.yaml",
         (_LEADER_INPUT, "controller.leader_information={command: false, estimator: true}"),
         note="leader input u_1 told to the estimator, not fed forward"),
    Case("leader_input_unshared", "paper_run2.yaml", (_LEADER_INPUT,),
         note="leader input u_1 unknown to the follower"),
    Case("share_dist_command", "paper_run2.yaml",
         (_sharing(command=True, disturbance=True),),
         note="a_1 = u_1 + pinv(B) u_d fed forward: only the position-rate half moves xi"),
    Case("share_dist_estimator", "paper_run2.yaml",
         (_sharing(estimator=True, disturbance=True),),
         note="a_1 = u_1 + pinv(B) u_d in the estimator's model of xi'"),
    Case("share_dist_both", "paper_run2.yaml",
         (_sharing(command=True, estimator=True, disturbance=True),),
         note="a_1 fed forward and told to the estimator"),
    Case("share_dist_pos_rate", "paper_run2.yaml",
         (_sharing(command=True, disturbance=True), "leader.disturbance.0.vector=[-2.0, 0.0]"),
         note="pure position-rate pulse: pinv(B) u_d = 0, nothing to feed forward"),
    Case("share_dist_vel_rate", "paper_run2.yaml",
         (_sharing(command=True, disturbance=True), "leader.disturbance.0.vector=[0.0, -2.0]"),
         note="pure velocity-rate pulse fed forward: xi stays 0"),
    Case("share_dist_rotated_2d", "paper_run2.yaml",
         _rotated_2d(60.0) + (_sharing(command=True, disturbance=True),),
         note="run 2 in 2-D rotated by 60 deg, a_1 with pinv(B) u_d fed forward"),
    Case("rotated_2d_run1", "paper_run1.yaml", _rotated_2d(30.0),
         note="run 1 in 2-D, every vector rotated by 30 deg"),
    Case("rotated_2d_run2", "paper_run2.yaml", _rotated_2d(-115.0),
         note="run 2 in 2-D, every vector rotated by -115 deg"),
)


def tool_command(path):
    """argv prefix that runs a tool; Python scripts go through /usr/bin/python3."""
    return [PYTHON, str(path)] if str(path).endswith(".py") else [str(path)]


def parse_summary(stdout):
    """The key=value pairs of the last stdout line that has a max_xi= entry."""
    for line in reversed(stdout.splitlines()):
        pairs = dict(tok.split("=", 1) for tok in line.split() if "=" in tok)
        if "max_xi" in pairs:
            try:
                return {k: float(v) for k, v in pairs.items()}
            except ValueError as exc:
                raise ValueError(f"bad value in summary line '{line.strip()}': {exc}") from None
    raise ValueError("no summary line (key=value with max_xi) on stdout")


def run_tool(tool, scenario_path, overrides, extra_args=()):
    """Run one tool on a case; return (summary dict, None) or (None, error text)."""
    argv = tool_command(tool) + [str(scenario_path)] + list(extra_args)
    for assignment in overrides:
        argv += ["--set", assignment]
    try:
        proc = subprocess.run(argv, capture_output=True, text=True, timeout=TIMEOUT_S)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return None, f"{Path(tool).name}: {exc}"
    if proc.returncode != 0:
        err = (proc.stderr.strip().splitlines() or ["(no stderr)"])[-1]
        return None, f"{Path(tool).name} exited {proc.returncode}: {err}"
    try:
        summary = parse_summary(proc.stdout)
    except ValueError as exc:
        return None, f"{Path(tool).name}: {exc}"
    missing = [k for k in REQUIRED if k not in summary]
    if missing:
        return None, f"{Path(tool).name}: summary lacks {', '.join(missing)}"
    return summary, None


def check_case(case, cf_sim, reference, scenarios_dir, tolerance, cf_args=(), ref_args=()):
    """Run both tools on a case; return (passed, report line)."""
    scenario = scenarios_dir / case.scenario
    if not scenario.is_file():
        return False, f"FAIL {case.name}: no scenario file {scenario}"
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        cf_future = pool.submit(run_tool, cf_sim, scenario, case.overrides, cf_args)
        ref_future = pool.submit(run_tool, reference, scenario, case.overrides, ref_args)
        (cf, cf_err), (ref, ref_err) = cf_future.result(), ref_future.result()
    if cf_err or ref_err:
        return False, f"FAIL {case.name}: " + "; ".join(e for e in (cf_err, ref_err) if e)

    problems = []
    parts = []
    for key in COMPARED:
        diff = abs(cf[key] - ref[key])
        parts.append(f"{key}={cf[key]:.4f}/{ref[key]:.4f} (d={diff:.1e})")
        if not diff <= tolerance:
            problems.append(f"{key} differs by {diff:.3g} m > {tolerance:g}")
    if not abs(cf["xi_max"] - ref["xi_max"]) <= 1e-9 * max(1.0, abs(ref["xi_max"])):
        problems.append(f"xi_max {cf['xi_max']:.9g} != reference {ref['xi_max']:.9g}")
    if not cf["max_xi_hat"] <= cf["xi_max"] + BOUND_SLACK:
        problems.append(f"cf_sim max_xi_hat {cf['max_xi_hat']:.9g} exceeds "
                        f"xi_max {cf['xi_max']:.9g} by {cf['max_xi_hat'] - cf['xi_max']:.3g}")
    status = "FAIL" if problems else "ok  "
    line = f"{status} {case.name:<22} cf_sim/reference: " + " ".join(parts)
    if problems:
        line += " -- " + "; ".join(problems)
    return not problems, line


def parse_args(argv):
    ap = argparse.ArgumentParser(
        prog="compare_with_reference.py",
        description="Compare cf_sim's summary with the continuous-time reference on a set "
                    "of scenario variants.")
    ap.add_argument("--cf-sim", required=True, metavar="PATH",
                    help="the cf_sim executable (a .py path is run with /usr/bin/python3)")
    ap.add_argument("--scenarios-dir", required=True, type=Path, metavar="DIR",
                    help="directory holding paper_run1.yaml and paper_run2.yaml")
    ap.add_argument("--tolerance", type=float, default=0.02,
                    help="largest allowed difference of max_xi, max_xi_hat, min_separation, m "
                         "(default 0.02)")
    ap.add_argument("--reference", default=str(DEFAULT_REFERENCE), metavar="PATH",
                    help="reference simulator (default: reference_sim.py beside this file)")
    ap.add_argument("--cf-sim-arg", action="append", default=[], metavar="ARG",
                    help="extra argument for cf_sim, e.g. --cf-sim-arg=--foo (repeatable)")
    ap.add_argument("--reference-arg", action="append", default=[], metavar="ARG",
                    help="extra argument for the reference, e.g. --reference-arg=--rtol=1e-9 "
                         "(repeatable)")
    ap.add_argument("--case", action="append", default=[], metavar="NAME",
                    help="run only this case (repeatable); see --list")
    ap.add_argument("--jobs", type=int, default=max(1, (os.cpu_count() or 2) // 2),
                    help="cases run in parallel (each runs both tools at once)")
    ap.add_argument("--xunit", metavar="FILE",
                    help="also write the results as a JUnit XML file")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    return ap.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    if args.list:
        for case in CASES:
            print(f"{case.name:<22} {case.scenario:<16} {case.note}")
            for assignment in case.overrides:
                print(f"{'':<22}   --set {assignment}")
        return 0
    known = {c.name for c in CASES}
    unknown = [n for n in args.case if n not in known]
    if unknown:
        print(f"compare_with_reference: error: unknown case {', '.join(unknown)} "
              f"(known: {', '.join(sorted(known))})", file=sys.stderr)
        return 2
    if not args.tolerance >= 0:
        print("compare_with_reference: error: --tolerance must be >= 0", file=sys.stderr)
        return 2
    cases = [c for c in CASES if not args.case or c.name in args.case]

    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = [pool.submit(check_case, c, args.cf_sim, args.reference,
                               args.scenarios_dir, args.tolerance,
                               args.cf_sim_arg, args.reference_arg) for c in cases]
        passed = failed = 0
        results = []
        for case, future in zip(cases, futures):  # report in case order
            ok, line = future.result()
            print(line, flush=True)
            results.append((case.name, ok, line))
            passed += ok
            failed += not ok
    print(f"{passed} passed, {failed} failed")
    if args.xunit:
        write_xunit(args.xunit, results)
    return 1 if failed else 0


def write_xunit(path, results):
    """Writes the cases as a JUnit XML file (read by catkin_test_results)."""
    import xml.etree.ElementTree as ET
    suite = ET.Element("testsuite", name="compare_with_reference", tests=str(len(results)),
                       failures=str(sum(1 for _, ok, _ in results if not ok)), errors="0")
    for name, ok, line in results:
        case = ET.SubElement(suite, "testcase", classname="compare_with_reference", name=name)
        if not ok:
            ET.SubElement(case, "failure", message=line).text = line
        else:
            ET.SubElement(case, "system-out").text = line
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    ET.ElementTree(suite).write(path, encoding="utf-8", xml_declaration=True)


if __name__ == "__main__":
    sys.exit(main())
