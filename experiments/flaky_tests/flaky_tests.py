#!/usr/bin/python3
"""Tabulates the failures of experiments/flaky_tests/run.sh: every run_<i>/ of OUT_DIR holds a
ctest log and the JUnit files of one run of the suite.

Writes CSV (run, test, case, message: one row per failing test case, none when a run passed) and,
with --update, the table between the markers of a markdown file (doc/testing.md): per run its
time, its test cases and their failures, then every test that failed with the runs it failed in.

Usage: flaky_tests.py OUT_DIR --out CSV --runs N --load CPUS --jobs J [--update MD]
"""

import argparse
import csv
import pathlib
import re
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "common"))
from doc_block import replace_block  # noqa: E402 (from experiments/common/)

BEGIN = "<!-- flaky-tests: begin (experiments/flaky_tests/run.sh) -->"
END = "<!-- flaky-tests: end -->"
TOTAL = re.compile(r"Total Test time \(real\) = +(?P<seconds>[0-9.]+) sec")


def read_run(directory):
    """(seconds, cases, [(file, case, message)]) of one run."""
    log = (directory / "ctest.log").read_text(errors="replace")
    match = TOTAL.search(log)
    seconds = float(match["seconds"]) if match else float("nan")
    cases = 0
    failures = []
    for path in sorted((directory / "test_results").rglob("*.xml")):
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError as error:  # a test killed while writing its file
            failures.append((path.stem, "(results file)", f"unreadable: {error}"))
            continue
        for case in root.iter("testcase"):
            cases += 1
            problem = case.find("failure")
            if problem is None:
                problem = case.find("error")
            if problem is not None:
                text = (problem.get("message") or problem.text or "").strip()
                failures.append((path.stem, case.get("name"), " ".join(text.split())[:300]))
    return seconds, cases, failures


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out_dir")
    parser.add_argument("--out", required=True)
    parser.add_argument("--runs", type=int, required=True)
    parser.add_argument("--load", type=int, required=True)
    parser.add_argument("--jobs", type=int, required=True)
    parser.add_argument("--update")
    args = parser.parse_args()
    runs = sorted(pathlib.Path(args.out_dir).glob("run_*"), key=lambda p: int(p.name[4:]))
    if len(runs) != args.runs:
        sys.exit(f"{args.out_dir}: {len(runs)} runs, expected {args.runs}")
    table = []
    with open(args.out, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["run", "test", "case", "message"])
        for index, run in enumerate(runs, 1):
            seconds, cases, failures = read_run(run)
            table.append((index, seconds, cases, failures))
            for test, case, message in failures:
                writer.writerow([index, test, case, message])
    lines = [f"{args.runs} runs of the whole ctest suite in a row, `ctest -j{args.jobs}`, "
             f"{args.load} `stress-ng --cpu` workers busy throughout "
             f"(`experiments/flaky_tests/run.sh`; every failure in `doc/flaky_tests.csv`):", "",
             "| run | ctest (s) | test cases | failed |", "|---|---|---|---|"]
    by_test = {}
    for index, seconds, cases, failures in table:
        lines.append(f"| {index} | {seconds:.0f} | {cases} | {len(failures)} |")
        for test, case, _ in failures:
            by_test.setdefault(f"{test} / {case}", []).append(index)
    lines.append("")
    if by_test:
        lines += ["| failed test case | in runs |", "|---|---|"]
        lines += [f"| {name} | {', '.join(map(str, sorted(set(r))))} |"
                  for name, r in sorted(by_test.items())]
    else:
        lines.append("No test case failed.")
    text = "\n".join(lines)
    print(text)
    if args.update:
        replace_block(args.update, BEGIN, END, text)


if __name__ == "__main__":
    main()
