#!/usr/bin/python3
"""What the comparison scripts (compare_with_reference.py, compare_convoy.py) share: running a
tool on a case and reading its summary lines, and the JUnit XML file catkin_test_results reads."""

import os
import subprocess
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
