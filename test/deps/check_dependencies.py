#!/usr/bin/python3
"""Checks that scripts/debian-packages.txt and package.xml declare everything the package uses.

Usage::

    check_dependencies.py [--root DIR] [--xunit FILE]

Read from the sources, not from memory:

  * every module imported by a Python file of the package (``import``/``from``, at any depth),
  * every Python module the package's own messages import (the ``pkg/Type`` fields of msg/),
  * every ``<node>``/``<test>`` of the launch and test files (its ``pkg``, ``type`` and
    ``launch-prefix``),
  * every command the shell scripts run (first word of each simple command) and every program a
    Python file starts (the first element of a subprocess call; ``rosrun PKG EXE``).

Each is resolved on this machine (``importlib``, ``rospkg``, ``PATH``) to the file that provides
it and, through ``dpkg -S``, to its Debian package. A check fails when

  * the thing is not installed at all (the file is missing),
  * its Debian package is neither in scripts/debian-packages.txt (itself or as a direct
    dependency of a listed package) nor of priority "required" (in every Debian root), or
  * package.xml does not declare it: a ROS package by its name, anything else by its rosdep key
    (the Debian package's name), as ``depend``/``exec_depend`` (``test_depend`` will do for what
    only tests use).

One JUnit test case per use is written with --xunit (read by catkin_test_results); the exit
status is 1 when a check fails.
"""

from __future__ import annotations

import argparse
import ast
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from debian_lookup import (debian_package, priority, providing_file, reverse_dependencies,
                           ros_packages_in)
from shell_commands import simple_commands

PACKAGE = "projection_collision_avoidance"
SKIPPED_DIRS = {".git", "build", "build-sanitize", "devel", "install", "log", "out", "__pycache__"}
SUBPROCESS_CALLS = {"run", "Popen", "call", "check_call", "check_output"}
# Programs that run the rest of their arguments as a command: (positional arguments before the
# command, options that take a value).
WRAPPERS = {"exec": (0, set()), "sudo": (0, {"-u", "-g"}), "nohup": (0, set()),
            "env": (0, {"-u"}), "command": (0, set()), "nice": (0, {"-n"}),
            "timeout": (1, {"-s", "--signal", "-k", "--kill-after"}), "chrt": (1, set()),
            "taskset": (1, set())}
# Scripts that build, test and measure the package: what only they use may be a test_depend.
DEVELOPMENT_SCRIPTS = {"scripts/test.sh", "scripts/build.sh", "scripts/sanitize.sh",
                       "scripts/setup.sh", "scripts/check_workspace.sh", "scripts/workspace.sh",
                       "scripts/quick_test.sh",
                       "experiments/flaky_tests/run.sh", "experiments/flaky_tests/flaky_tests.py",
                       "experiments/ci_time/run.sh", "experiments/ci_time/ci_phases.py",
                       "experiments/performance/run.sh",
                       "experiments/performance/performance_report.py",
                       "experiments/performance/solver_comparison.py",
                       "experiments/ros_latency/run.sh", "experiments/ros_latency/ros_latency.py",
                       "experiments/fault_table/run.sh", "experiments/node_cpu/run.sh",
                       "experiments/node_cpu/node_cpu.py", "experiments/node_cpu/callgrind.sh",
                       "experiments/node_cpu/callgrind_parts.py",
                       "experiments/node_cpu/platoon_cpu.py", "experiments/node_cpu/all.sh",
                       "experiments/node_cpu/threads.py"}
# Files under test/ that the package installs as programs: what they use is a run-time need.
INSTALLED_PROGRAMS = {"test/reference/reference_sim.py"}
# The experiments' shared Python helpers, imported by the experiments as local modules.
EXPERIMENT_HELPERS = Path("experiments") / "common"
# Debian packages used by the scripts but not dependencies of the package: catkin's own
# toolchain, and the workspace tools a user picks. They are in scripts/debian-packages.txt.
TOOLCHAIN = {"make", "cmake", "catkin", "catkin-tools", "colcon", "python3-colcon-ros",
             "python3-colcon-bash", "git", "ccache"}
COMMAND_WORD = re.compile(r"^[A-Za-z][A-Za-z0-9_.+-]*$")


@dataclass(frozen=True)
class Use:
    """One thing the package uses, and where."""
    kind: str      # "python module", "command", "ROS executable"
    name: str
    where: str     # file:line
    test_only: bool


def bash_builtins():
    out = subprocess.run(["bash", "-c", "compgen -b; compgen -k"], capture_output=True, text=True)
    return set(out.stdout.split())


def source_files(root, suffixes):
    for directory, subdirs, files in os.walk(root):
        subdirs[:] = sorted(d for d in subdirs if d not in SKIPPED_DIRS)
        for name in sorted(files):
            if Path(name).suffix in suffixes:
                yield Path(directory) / name


def is_test_path(root, path):
    """Tests, and the scripts that build, test and measure the package (not run by its users)."""
    relative = Path(path).relative_to(root)
    if relative.as_posix() in INSTALLED_PROGRAMS:
        return False
    return relative.parts[0] in ("test", ".ci") or relative.as_posix() in DEVELOPMENT_SCRIPTS


# ----------------------------------------------------------------------------------------------
# Reading the sources


def python_uses(root, path):
    """Imports and started programs of one Python file."""
    tree = ast.parse(path.read_text(), filename=str(path))
    local = {p.stem for p in path.parent.glob("*.py")}
    if path.relative_to(root).parts[0] == EXPERIMENT_HELPERS.parts[0]:
        local |= {p.stem for p in (root / EXPERIMENT_HELPERS).glob("*.py")}
    test_only = is_test_path(root, path)
    where = lambda node: f"{path.relative_to(root)}:{node.lineno}"  # noqa: E731
    for node in ast.walk(tree):
        names = []
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module]
        for name in names:
            top = name.split(".")[0]
            if top in sys.stdlib_module_names or top == "__future__" or top in local:
                continue
            if top == PACKAGE:
                # The package's own generated messages: what they import is checked from msg/.
                continue
            yield Use("python module", top, where(node), test_only)
        if isinstance(node, ast.Call) and call_name(node.func) in SUBPROCESS_CALLS and node.args:
            argv = node.args[0]
            while isinstance(argv, ast.BinOp):  # ["prog", ...] + more
                argv = argv.left
            elements = getattr(argv, "elts", [])
            words = [e.value for e in elements
                     if isinstance(e, ast.Constant) and isinstance(e.value, str)]
            if words and isinstance(elements[0], ast.Constant):
                yield from command_uses(words, where(node), test_only)


def call_name(func):
    if isinstance(func, ast.Attribute):
        return func.attr
    if isinstance(func, ast.Name):
        return func.id
    return ""


def command_uses(words, where, test_only):
    """The programs of one command line given as words (wrappers and rosrun unwrapped)."""
    while words:
        word = words[0]
        if word in WRAPPERS and len(words) > 1:
            yield Use("command", word, where, test_only)
            positional, valued = WRAPPERS[word]
            rest = words[1:]
            while rest and (rest[0].startswith("-") or re.match(r"^\w+=", rest[0])):
                rest = rest[2:] if rest[0] in valued else rest[1:]
            words = rest[positional:]
            continue
        if word == "rosrun" and len(words) >= 3:
            yield Use("command", "rosrun", where, test_only)
            if words[1] != PACKAGE and not words[1].startswith("$"):
                yield Use("ROS executable", f"{words[1]}/{words[2]}", where, test_only)
            return
        if "/" not in word and COMMAND_WORD.match(word):
            yield Use("command", word, where, test_only)
        return


def shell_functions(paths):
    """The names of the functions the shell files define (scripts source each other)."""
    names = set()
    for path in paths:
        names |= set(re.findall(r"^\s*(?:function\s+)?([A-Za-z_][A-Za-z0-9_]*)\s*\(\)",
                                path.read_text(), re.M))
    return names


def shell_uses(root, path, builtins, functions):
    """The programs one shell script runs: the first word of each simple command."""
    text = path.read_text()
    test_only = is_test_path(root, path)
    for line, words in simple_commands(text):
        while words and re.match(r"^[A-Za-z_][A-Za-z0-9_]*(\[.*\])?\+?=", words[0]):
            words = words[1:]
        if not words or words[0] in builtins or words[0] in functions or words[0] in ("[[", "["):
            continue
        yield from command_uses(words, f"{path.relative_to(root)}:{line}", test_only)


def launch_uses(root, path):
    """The nodes and tests of one launch or test file from other packages, and their prefixes."""
    test_only = is_test_path(root, path)
    where = str(path.relative_to(root))
    try:
        root_element = ET.parse(path).getroot()
    except ET.ParseError as error:
        raise SystemExit(f"check_dependencies: {path}: {error}") from error
    for element in root_element.iter():
        if element.tag not in ("node", "test"):
            continue
        pkgs = choices(element.get("pkg", ""))
        types = choices(element.get("type", ""))
        pairs = zip(pkgs, types) if len(pkgs) == len(types) else (
            (p, t) for p in pkgs for t in types)
        for pkg, executable in pairs:
            if pkg != PACKAGE:
                yield Use("ROS executable", f"{pkg}/{executable}", where, test_only)
        prefix = element.get("launch-prefix", "")
        if prefix and not prefix.startswith("$"):
            yield from command_uses(prefix.split(), where, test_only)
        elif prefix:
            # An argument: its documented example (e.g. 'chrt -f 50') is checked.
            pass


def choices(expression):
    """The values an attribute can take: its text, or the quoted results of a $(eval ...)."""
    if expression.startswith("$(eval"):
        return re.findall(r"(?<!arg\()'([A-Za-z0-9_]+)'", expression)
    return [expression] if expression else []


def message_uses(root):
    for path in source_files(root / "msg", {".msg"}):
        for number, line in enumerate(path.read_text().split("\n"), 1):
            match = re.match(r"\s*([a-z][a-z0-9_]*)/[A-Za-z]", line)
            if match and match.group(1) != PACKAGE:
                yield Use("python module", match.group(1), f"{path.relative_to(root)}:{number}",
                          True)


def all_uses(root):
    builtins = bash_builtins()
    for path in source_files(root, {".py"}):
        yield from python_uses(root, path)
    shell_files = list(source_files(root, {".sh", ".bash"}))
    shell_files += [path for path in [root / ".ci" / "run"] if path.exists()]
    functions = shell_functions(shell_files)
    for path in shell_files:
        yield from shell_uses(root, path, builtins, functions)
    for path in source_files(root, {".launch", ".test"}):
        yield from launch_uses(root, path)
    yield from message_uses(root)


def listed_packages(root):
    listed = set()
    for line in (root / "scripts" / "debian-packages.txt").read_text().split("\n"):
        line = line.split("#")[0].strip()
        if line:
            listed.add(line.split()[0])
    return listed


def declared_keys(root):
    """package.xml's keys: name -> set of tags (depend, exec_depend, test_depend, ...)."""
    keys = {}
    for element in ET.parse(root / "package.xml").getroot():
        if element.tag.endswith("depend") and element.text:
            keys.setdefault(element.text.strip(), set()).add(element.tag)
    return keys


def rosdep_key(use, package):
    """The name package.xml knows a use by: its ROS package, else the Debian package's name."""
    if use.kind == "ROS executable":
        return use.name.split("/")[0]
    if use.kind == "python module" and Path(f"/usr/share/{use.name}/package.xml").exists():
        return use.name
    ros = ros_packages_in(package)
    return ros[0] if len(ros) == 1 else package


def check(use, listed, keys):
    """None when the use is covered, else what is missing."""
    path = providing_file(use.kind, use.name)
    if path is None:
        return f"{use.kind} {use.name} is not installed (used at {use.where})"
    package = debian_package(path)
    if package is None:
        return f"{use.kind} {use.name} ({path}) belongs to no Debian package"
    if priority(package) == "required":
        return None
    if package not in listed:
        through = sorted(listed & reverse_dependencies(package))
        if not through:
            return (f"{use.kind} {use.name} comes from Debian package {package}, "
                    f"missing from scripts/debian-packages.txt (used at {use.where})")
        package = through[0]
    if package in TOOLCHAIN:
        return None
    key = rosdep_key(use, package)
    allowed = {"depend", "exec_depend"} | ({"test_depend"} if use.test_only else set())
    if not keys.get(key, set()) & allowed:
        return (f"{use.kind} {use.name} (Debian {package}) is not declared in package.xml: "
                f"add <{'test_depend' if use.test_only else 'exec_depend'}>{key}</...> "
                f"(used at {use.where})")
    return None


def write_xunit(path, results, suite_name="dependencies"):
    """Writes (name, problem or None) pairs as one JUnit suite: a test case per pair."""
    suite = ET.Element("testsuite", name=suite_name, tests=str(len(results)),
                       failures=str(sum(1 for _, problem in results if problem)), errors="0")
    for name, problem in results:
        case = ET.SubElement(suite, "testcase", classname=suite_name, name=name)
        if problem:
            ET.SubElement(case, "failure", message=problem).text = problem
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    ET.ElementTree(suite).write(path, encoding="utf-8", xml_declaration=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", type=Path, default=Path(__file__).resolve().parents[2],
                    help="the package's source directory")
    ap.add_argument("--xunit", metavar="FILE", help="also write the results as JUnit XML")
    ap.add_argument("--verbose", action="store_true", help="print every use and its package")
    args = ap.parse_args(argv)
    root = args.root.resolve()
    listed, keys = listed_packages(root), declared_keys(root)

    # One result per distinct thing used; a thing only tests use may be a test_depend.
    uses = {}
    for use in all_uses(root):
        key = (use.kind, use.name)
        if key in uses:
            uses[key] = Use(use.kind, use.name, uses[key].where,
                            uses[key].test_only and use.test_only)
        else:
            uses[key] = use
    results = []
    for (kind, name), use in sorted(uses.items()):
        problem = check(use, listed, keys)
        results.append((f"{kind} {name}", problem))
        if problem:
            print(f"FAIL {problem}")
        elif args.verbose:
            path = providing_file(kind, name)
            print(f"ok   {kind} {name}: {debian_package(path)} ({use.where})")
    failed = sum(1 for _, problem in results if problem)
    print(f"dependencies: {len(results) - failed} of {len(results)} uses covered")
    if args.xunit:
        write_xunit(args.xunit, results)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
