#!/usr/bin/python3
"""What the comparison scripts (compare_with_reference.py, compare_convoy.py,
compare_neighbours.py, compare_barrier_filter.py) share: running a tool on a case and reading its
summary lines, the command line and the run of a list of cases, and the JUnit XML file
catkin_test_results reads."""

import argparse
import concurrent.futures
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

PYTHON = "/usr/bin/python3"
TIMEOUT_S = 300


def tool_command(path):
    """argv prefix that runs a tool; Python scripts go through /usr/bin/python3."""
    return [PYTHON, str(path)] if str(path).endswith(".py") else [str(path)]


def run_tool(tool, argv, overrides, parse, parse_errors=(ValueError,), timeout=TIMEOUT_S):
    """Runs TOOL with ARGV and a --set per override; returns (parse(stdout), None) or (None,
    error text) within TIMEOUT seconds: the tool's failure to start or finish, its exit status with its last stderr
    line, or PARSE's error."""
    argv = tool_command(tool) + [str(arg) for arg in argv]
    for assignment in overrides:
        argv += ["--set", assignment]
    try:
        proc = subprocess.run(argv, capture_output=True, text=True, timeout=timeout)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return None, f"{Path(tool).name}: {exc}"
    if proc.returncode != 0:
        err = (proc.stderr.strip().splitlines() or ["(no stderr)"])[-1]
        return None, f"{Path(tool).name} exited {proc.returncode}: {err}"
    try:
        return parse(proc.stdout), None
    except parse_errors as exc:
        return None, f"{Path(tool).name}: {exc}"


def run_both(cf_sim, reference, scenario, work, overrides, parse):
    """cf_sim and the reference side by side on SCENARIO with the overrides, each writing its CSV
    into WORK (cf_sim.csv, reference.csv); returns (cf_sim's parse(stdout), the reference's, the
    error text of either, '' if none)."""
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        jobs = [pool.submit(run_tool, tool, [scenario, "--csv", Path(work) / f"{label}.csv"],
                            overrides, parse, (ValueError, KeyError))
                for tool, label in ((cf_sim, "cf_sim"), (reference, "reference"))]
        (cf, cf_err), (ref, ref_err) = jobs[0].result(), jobs[1].result()
    return cf, ref, "; ".join(e for e in (cf_err, ref_err) if e)


def write_xunit(path, suite_name, results):
    """Writes RESULTS, (name, ok, line) per case, as the suite SUITE_NAME to PATH."""
    suite = ET.Element("testsuite", name=suite_name, tests=str(len(results)),
                       failures=str(sum(1 for _, ok, _ in results if not ok)), errors="0")
    for name, ok, line in results:
        case = ET.SubElement(suite, "testcase", classname=suite_name, name=name)
        if not ok:
            ET.SubElement(case, "failure", message=line).text = line
        else:
            ET.SubElement(case, "system-out").text = line
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    ET.ElementTree(suite).write(path, encoding="utf-8", xml_declaration=True)


def case_parser(prog, description, reference, tolerance=True):
    """The command line of a cf_sim-against-reference comparison: --cf-sim, --scenarios-dir,
    --reference (default @p reference), [--tolerance], --case, --jobs, --xunit, --keep, --list."""
    ap = argparse.ArgumentParser(prog=prog, description=description)
    ap.add_argument("--cf-sim", required=True, metavar="PATH")
    ap.add_argument("--scenarios-dir", required=True, type=Path, metavar="DIR")
    ap.add_argument("--reference", default=str(reference), metavar="PATH")
    if tolerance:
        ap.add_argument("--tolerance", type=float, metavar="M",
                        help="tolerance for every case instead of each case's own")
    ap.add_argument("--case", action="append", default=[], metavar="NAME")
    ap.add_argument("--jobs", type=int, default=2, help="cases run in parallel")
    ap.add_argument("--xunit", metavar="FILE", help="also write a JUnit XML file")
    ap.add_argument("--keep", metavar="DIR", help="keep the CSVs in DIR/<case>/")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    return ap


def run_cases(suite, cases, args, check, describe, width, first=None):
    """--list (a line @p describe(case) and its --set lines, indented by @p width, per case),
    or @p check(case) -> (passed, line) for the cases --case names (all by default), @p args.jobs at a time (those
    for which @p first(case) is true started first), each line printed in the list's order,
    then "N passed, M failed" and the --xunit file of suite @p suite. Returns the exit status:
    0, 1 if a case failed, 2 for an unknown case."""
    if args.list:
        for case in cases:
            print(describe(case))
            for assignment in case.overrides:
                print(f"{'':<{width}}   --set {assignment}")
        return 0
    unknown = sorted(set(args.case) - {c.name for c in cases})
    if unknown:
        print(f"{suite}: error: unknown case {', '.join(unknown)}", file=sys.stderr)
        return 2
    chosen = [c for c in cases if not args.case or c.name in args.case]
    order = sorted(chosen, key=lambda c: not first(c)) if first else chosen
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = {c.name: pool.submit(check, c) for c in order}
        results = []
        for case in chosen:
            ok, line = futures[case.name].result()
            print(line, flush=True)
            results.append((case.name, ok, line))
    failed = sum(1 for _, ok, _ in results if not ok)
    print(f"{len(results) - failed} passed, {failed} failed")
    if args.xunit:
        write_xunit(args.xunit, suite, results)
    return 1 if failed else 0
