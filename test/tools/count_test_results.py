#!/usr/bin/python3
"""Counts the test cases in the JUnit XML files under a directory (gtest, rostest, xunit):
prints "passed failed skipped". Used by scripts/test.sh and scripts/sanitize.sh."""

import pathlib
import sys
import xml.etree.ElementTree as ET


def count(directory):
    passed = failed = skipped = 0
    for path in pathlib.Path(directory).rglob("*.xml"):
        for case in ET.parse(path).getroot().iter("testcase"):
            if case.find("failure") is not None or case.find("error") is not None:
                failed += 1
            elif case.find("skipped") is not None or case.get("status") == "notrun":
                skipped += 1
            else:
                passed += 1
    return passed, failed, skipped


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: count_test_results.py DIRECTORY")
    print(*count(sys.argv[1]))
