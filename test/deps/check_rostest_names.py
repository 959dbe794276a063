#!/usr/bin/python3
"""Checks that no two rostests of the build write the same results file.

Usage::

    check_rostest_names.py --build DIR [--xunit FILE]

rostest writes a test node's results to ``rosunit-<test-name>.xml`` in the package's results
directory, removing that file before the node starts and reading it after the node ends. Two
rostests whose ``<test test-name=...>`` come out the same (one launch file added twice with
different ARGS, its test-name not naming them) share that file: run side by side (``ctest -j``),
one removes or overwrites the other's results, and the other fails with "did not generate test
results" or passes on results that are not its own.

The rostests are read from the build's ctest list (``ctest --show-only=json-v1``), each launch
file is loaded as rostest loads it, with the test's own arguments, and the test names compared.
One JUnit test case per rostest is written with --xunit; the exit status is 1 when two clash.
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import subprocess
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_dependencies import write_xunit  # noqa: E402


def rostest_commands(build):
    """(ctest name, launch file, [name:=value, ...]) of every rostest ctest knows in BUILD."""
    listing = subprocess.run(["ctest", "--show-only=json-v1"], cwd=build, check=True,
                             capture_output=True, text=True).stdout
    for test in json.loads(listing).get("tests", []):
        words = [w for part in test.get("command", []) for w in shlex.split(part)]
        if not any(os.path.basename(w) == "rostest" for w in words):
            continue
        launch = next((w for w in words if w.endswith(".test") and os.path.isfile(w)), None)
        if launch is None:
            continue
        args = [w for w in words[words.index(launch) + 1:] if ":=" in w]
        yield test["name"], launch, args


def test_names(launch, args):
    """The test-names of the launch file's <test>s when started with ARGS, as rostest reads them."""
    import roslaunch.config  # pylint: disable=import-outside-toplevel

    saved = sys.argv
    sys.argv = [saved[0]] + list(args)  # roslaunch reads name:=value arguments from sys.argv
    try:
        config = roslaunch.config.load_config_default([launch], None)
    finally:
        sys.argv = saved
    return [test.test_name for test in config.tests]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", required=True, help="the package's build directory (ctest's)")
    ap.add_argument("--xunit", metavar="FILE", help="also write the results as JUnit XML")
    args = ap.parse_args(argv)

    owners = defaultdict(list)  # test-name -> the ctest tests that give it
    loaded = []  # (ctest name, its test-names)
    checked = []  # (ctest name, problem or None)
    for ctest_name, launch, launch_args in rostest_commands(args.build):
        try:
            names = test_names(launch, launch_args)
        except Exception as error:  # pylint: disable=broad-except
            checked.append((ctest_name, f"{launch} {' '.join(launch_args)} did not load: {error}"))
            continue
        for name in names:
            owners[name].append(ctest_name)
        loaded.append((ctest_name, names))
    for ctest_name, names in loaded:
        clashes = sorted({other for name in names for other in owners[name]} - {ctest_name})
        problem = None
        if clashes:
            problem = (f"test-name {', '.join(names)} is also that of {', '.join(clashes)}: both "
                       "write rosunit-<test-name>.xml; name the launch arguments in test-name")
        checked.append((ctest_name, problem))
        print(f"{ctest_name}: {', '.join(names)}" + (f": CLASH ({problem})" if problem else ""))
    if not checked:
        checked.append(("rostests_found", f"no rostest in the ctest list of {args.build}"))
    if args.xunit:
        write_xunit(args.xunit, checked, suite_name="rostest_names")
    failed = [name for name, problem in checked if problem]
    print(f"rostest names: {len(checked) - len(failed)} of {len(checked)} unique")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
