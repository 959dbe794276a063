#!/usr/bin/python3
"""Where the time of one `scripts/test.sh` run goes, read from its log.

Two kinds of log are read:
  - scripts/test.sh's own output (as `.ci/run` prints it): every phase starts with a line
    `== phase NAME (at S s)`, S the seconds since test.sh started; the run ends with
    `== phase end (at S s)`.
  - for a test.sh that printed no phase lines, a log whose every line starts with the Unix time it
    was printed (experiments/ci_time/run.sh writes one): a phase starts at each line that
    matches one of LEGACY_MARKERS.
A log may be gzipped (.gz).
The tests' own times come from ctest's lines (`N/M Test #K: NAME ... Passed 12.34 sec`) when the
log has them, or from the JUnit XML files of a results directory (--results), grouped by kind.

Usage:
  ci_phases.py phases LOG                     a table of the phases
  ci_phases.py tests (--log LOG | --results DIR) [--csv CSV]   the tests' times by group
  ci_phases.py report --before LOG [--before-results DIR|CSV] --after LOG
                      [--after-results DIR|CSV]
                      [--update FILE]         the markdown of doc/testing.md's section; with
                                              --update, written between its markers
"""

import argparse
import csv
import gzip
import pathlib
import re
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "common"))
from doc_block import replace_block  # noqa: E402 (from experiments/common/)

PHASE = re.compile(r"^== phase (?:\[(?P<lane>[^\]]+)\] )?(?P<name>.+) \(at (?P<at>\d+) s\)\s*$")
STAMPED = re.compile(r"^(?P<epoch>\d{10}) (?P<text>.*)$")
# Phase starts in the output of scripts/test.sh before it printed its own times.
LEGACY_MARKERS = [
    (re.compile(r"^fresh-debian-run: clean clone"), "setup"),
    (re.compile(r"^== standalone build and tests"), "build + tests: standalone, make run_tests"),
    (re.compile(r"^== multi-host tests"), "tests: multi-host"),
    (re.compile(r"^== workspace builds"), "build: catkin_make workspace"),
    (re.compile(r"^catkin_make: built"), "build: catkin build workspace"),
    (re.compile(r"^catkin_build: built"), "build: colcon workspace"),
    (re.compile(r"^== sanitizer build"), "sanitizers: build"),
    (re.compile(r"^== core gtests under ASan"), "sanitizers: gtests"),
    (re.compile(r"^== fuzz_follower_controller"), "sanitizers: fuzzing"),
    (re.compile(r"^fresh-debian-run: exit"), "end"),
]
CTEST = re.compile(r"^\s*\d+/\d+ Test +#\d+: (?P<name>\S+) .*?(?P<sec>\d+\.\d+) sec\s*$")
BEGIN = "<!-- ci-phases: begin (experiments/ci_time/ci_phases.py report) -->"
END = "<!-- ci-phases: end -->"


def read_lines(path):
    """The log's lines (a .gz file is read uncompressed)."""
    path = pathlib.Path(path)
    data = gzip.decompress(path.read_bytes()) if path.suffix == ".gz" else path.read_bytes()
    return data.decode(errors="replace").splitlines()


def read_phases(path):
    """[(name, seconds, lane)] in order: from test.sh's own phase lines where there are any, else
    from the Unix times of a stamped log's LEGACY_MARKERS. Lane "" is the run's own; a phase of
    another lane ran beside it (`== phase [LANE] NAME`), each lane ending with its own `end`."""
    lanes, legacy = {}, []
    for line in read_lines(path):
        stamped = STAMPED.match(line)
        text = stamped["text"] if stamped else line
        m = PHASE.match(text)
        if m:
            lanes.setdefault(m["lane"] or "", []).append((m["name"], float(m["at"])))
        elif stamped:
            for marker, name in LEGACY_MARKERS:
                if marker.match(text):
                    legacy.append((name, float(stamped["epoch"])))
    if not lanes and legacy:
        lanes[""] = legacy
    phases = []
    for lane, starts in lanes.items():
        if not starts or starts[-1][0] != "end":
            sys.exit(f"{path}: no end of {'the run' if not lane else lane} found (an unfinished "
                     "run?)")
        phases += [(name, nxt - at, lane) for (name, at), (_, nxt) in zip(starts, starts[1:])]
    if "" not in lanes:
        sys.exit(f"{path}: no phase of the run itself")
    return phases


def group_of(name):
    """The kind of a test from its ctest or file name."""
    found = []  # the kind named first: "..._python_rostest_names" is a Python check
    for kind in ("gtest", "rostest", "rosunit", "python", "multihost"):
        m = re.search(rf"(^|_){kind}[-_.]", name + "_")
        if m:
            found.append((m.start(), "rostest" if kind == "rosunit" else kind))
    return min(found)[1] if found else "other"


def tests_from_log(path):
    times = {}
    for line in read_lines(path):
        m = CTEST.match(STAMPED.sub(r"\g<text>", line))
        if m:
            group = group_of(m["name"])
            count, total = times.get(group, (0, 0.0))
            times[group] = (count + 1, total + float(m["sec"]))
    return times


def tests_from_results(directory):
    """Per group (tests, s) from the suites' time attributes (rosunit-* files repeat a rostest's
    inner suite and are skipped)."""
    times = {}
    for path in sorted(pathlib.Path(directory).rglob("*.xml")):
        if path.name.startswith("rosunit-"):
            continue
        root = ET.parse(path).getroot()
        suite = root if root.tag == "testsuite" else root.find("testsuite")
        seconds = float(suite.get("time", 0.0)) if suite is not None else 0.0
        group = group_of(path.name)
        count, total = times.get(group, (0, 0.0))
        times[group] = (count + 1, total + seconds)
    return times


def minutes(seconds):
    return f"{seconds / 60:.1f}"


def phases_table(before, after):
    """The phases of both runs, one row per name; a phase of another lane is marked so, and the
    total is the run's own lane, start to end."""
    names = []
    for name, _, _ in before + after:
        if name not in names:
            names.append(name)

    def cell(phases, name):
        found = [(seconds, lane) for n, seconds, lane in phases if n == name]
        if not found:
            return "—"
        seconds, lane = found[0]
        return minutes(seconds) + (f", {lane} (nice 19)" if lane else "")

    def total(phases):
        return minutes(sum(seconds for _, seconds, lane in phases if not lane))

    rows = ["| phase | before (min) | after (min) |", "|---|---|---|"]
    rows += [f"| {name} | {cell(before, name)} | {cell(after, name)} |" for name in names]
    rows.append(f"| **total** | **{total(before)}** | **{total(after)}** |")
    return "\n".join(rows)


def tests_table(before, after):
    rows = ["| tests | before: files or tests, summed min | after: files or tests, summed min |",
            "|---|---|---|"]
    for group in ("gtest", "python", "rostest", "multihost", "other"):
        if group in before or group in after:
            cells = []
            for times in (before, after):
                count, total = times.get(group, (0, 0.0))
                cells.append("—" if not count else
                             f"{count}, {minutes(total)}" if total > 0 else f"{count}, not timed")
            label = "other (the sanitizer build's gtest cases)" if group == "other" else group
            rows.append(f"| {label} | {cells[0]} | {cells[1]} |")
    return "\n".join(rows)


def test_times(log, results):
    """The tests' times of a run: from RESULTS (a folder of JUnit files, or a CSV of `tests
    --csv`) when given, else from ctest's lines in its log."""
    if not results:
        return tests_from_log(log)
    if results.endswith(".csv"):
        with open(results) as f:
            return {row["group"]: (int(row["tests"]), float(row["seconds"]))
                    for row in csv.DictReader(f)}
    return tests_from_results(results)


COUNTS = re.compile(r"(?P<passed>\d+) passed, (?P<failed>\d+) failed, \d+ skipped "
                    r"\(and under ASan \+ UBSan: (?P<sanitized>\d+) passed")


def counts(path):
    """The run's last line of counts: "P passed (+ S under ASan + UBSan), F failed"."""
    found = None
    for line in read_lines(path):
        m = COUNTS.search(line)
        if m:
            found = m
    if not found:
        return "no count"
    return (f"{found['passed']} passed + {found['sanitized']} under ASan + UBSan, "
            f"{found['failed']} failed")


def report(args):
    before, after = read_phases(args.before), read_phases(args.after)
    text = "\n\n".join([
        phases_table(before, after),
        f"Test cases (the run's last line): before {counts(args.before)}; after "
        f"{counts(args.after)}.",
        "A phase marked \"beside\" ran in a job of its own at nice 19, at the same time as the "
        "run's own phases (scripts/test.sh, step 2); a total is the run's own phases, start to "
        "end.",
        "Each group's tests, their own times summed (tests that run two at a time overlap, so a "
        "sum can exceed its phase):",
        tests_table(test_times(args.before, args.before_results),
                    test_times(args.after, args.after_results)),
    ])
    if not args.update:
        print(text)
        return
    replace_block(args.update, BEGIN, END, text)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("phases")
    p.add_argument("log")
    t = sub.add_parser("tests")
    t.add_argument("--log")
    t.add_argument("--results")
    t.add_argument("--csv", help="write the groups' times there")
    r = sub.add_parser("report")
    for which in ("before", "after"):
        r.add_argument(f"--{which}", required=True)
        r.add_argument(f"--{which}-results")
    r.add_argument("--update")
    args = parser.parse_args()
    if args.command == "phases":
        for name, seconds, lane in read_phases(args.log):
            print(f"{seconds:8.0f} s  {name}" + (f"  [{lane}]" if lane else ""))
    elif args.command == "tests":
        times = test_times(args.log, args.results)
        if args.csv:
            with open(args.csv, "w", newline="") as f:
                writer = csv.writer(f)
                writer.writerow(["group", "tests", "seconds"])
                for group, (count, total) in sorted(times.items()):
                    writer.writerow([group, count, f"{total:.1f}"])
        for group, (count, total) in sorted(times.items()):
            print(f"{group:10s} {count:4d} {total:8.0f} s")
    else:
        report(args)


if __name__ == "__main__":
    main()
