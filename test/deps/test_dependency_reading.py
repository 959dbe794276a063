#!/usr/bin/python3
"""Unit tests of the dependency check: how it reads shell, Python and launch files, and what it
refuses. Usage: test_dependency_reading.py [--xunit FILE]"""

from __future__ import annotations

import os
import sys
import tempfile
import textwrap
import unittest
import xml.etree.ElementTree as ET
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check_dependencies as deps  # noqa: E402
from shell_commands import simple_commands  # noqa: E402


def programs(script):
    """The first word of each simple command of a script."""
    return [words[0] for _, words in simple_commands(textwrap.dedent(script))]


class ShellReading(unittest.TestCase):
    def test_comments_and_quoted_text_are_no_commands(self):
        self.assertEqual(programs('echo "a; b | c" # rm x\n# make\nls \'x; y\'\n'), ["echo", "ls"])

    def test_command_substitutions_inside_quotes_are_read(self):
        self.assertEqual(programs('root=$(cd "$(dirname "$0")" && pwd)\n'),
                         ["dirname", "cd", "pwd", "root=$"])
        self.assertEqual(programs("x=`uname -r`\n"), ["uname", "x=$"])

    def test_here_document_bodies_are_skipped(self):
        self.assertEqual(programs("python3 - <<'PY'\nimport foo\nfoo.run()\nPY\nls\n"),
                         ["python3", "ls"])
        self.assertEqual(programs("cat <<-EOF\n\tmake all\n\tEOF\nls\n"), ["cat", "ls"])

    def test_case_patterns_are_no_commands(self):
        script = """
            case $x in
              a|b) make ;;
              --flag=*) cmake ;;
              *) echo x >&2; exit 2 ;;
            esac
            case $y in none|both) ;; *) valgrind ;; esac
            ls
            """
        self.assertEqual(programs(script), ["make", "cmake", "echo", "exit", "valgrind", "ls"])

    def test_continuations_arithmetic_and_parameters(self):
        self.assertEqual(programs("valgrind \\\n  --tool=callgrind prog\n"), ["valgrind"])
        self.assertEqual(programs("for (( i = 0; i < 3; i++ )); do ls; done\n"), ["ls"])
        self.assertEqual(programs('n=${2:?--n needs a value}; x=$((n + 1))\n'),
                         ["n=${2:?--n needs a value}", "x=0"])
        self.assertEqual(programs("(cd /tmp && make) || exit 1\n"), ["cd", "make", "exit"])

    def test_wrappers_and_rosrun_are_unwrapped(self):
        uses = list(deps.command_uses(["timeout", "-s", "INT", "5", "rosrun", "rviz", "rviz"],
                                      "x:1", False))
        self.assertEqual([(u.kind, u.name) for u in uses],
                         [("command", "timeout"), ("command", "rosrun"),
                          ("ROS executable", "rviz/rviz")])


class SourceReading(unittest.TestCase):
    def setUp(self):
        self.directory = tempfile.TemporaryDirectory()
        self.root = Path(self.directory.name)
        (self.root / "scripts").mkdir()

    def tearDown(self):
        self.directory.cleanup()

    def uses(self, name, text, reader):
        path = self.root / "scripts" / name
        path.write_text(textwrap.dedent(text))
        return sorted((u.kind, u.name) for u in reader(self.root, path))

    def test_python_imports_and_started_programs(self):
        (self.root / "scripts" / "helper.py").write_text("")  # a module beside it: not a package
        found = self.uses("tool.py", """
            import os, numpy.linalg
            from yaml import safe_load
            from . import sibling
            import helper
            def f(topics):
                import rosbag
                subprocess.Popen(["rosrun", "rosbag", "record"] + topics)
                subprocess.run(["valgrind", "--tool=callgrind", "x"], check=True)
                subprocess.run(command)
            """, deps.python_uses)
        self.assertEqual(found, [("ROS executable", "rosbag/record"), ("command", "rosrun"),
                                 ("command", "valgrind"), ("python module", "numpy"), ("python module", "rosbag"),
                                 ("python module", "yaml")])

    def test_launch_nodes_eval_choices_and_prefixes(self):
        found = self.uses("x.launch", """
            <launch>
              <node pkg="rviz" type="rviz" name="rviz"/>
              <node pkg="projection_collision_avoidance" type="follower_node" name="f"
                    launch-prefix="chrt -f 50"/>
              <node pkg="$(eval 'nodelet' if arg('n') else 'projection_collision_avoidance')"
                    type="$(eval 'nodelet' if arg('n') else 'follower_node')" name="g"/>
            </launch>
            """, deps.launch_uses)
        self.assertEqual(found, [("ROS executable", "nodelet/nodelet"),
                                 ("ROS executable", "rviz/rviz"), ("command", "chrt")])


class Verdicts(unittest.TestCase):
    """check() on real installed things, with package lists and keys made up for the test."""

    def use(self, name="yaml", test_only=False):
        return deps.Use("python module", name, "scripts/x.py:1", test_only)

    def test_a_package_missing_from_the_list_is_named(self):
        problem = deps.check(self.use(), set(), {})
        self.assertIn("python3-yaml, missing from scripts/debian-packages.txt", problem)

    def test_a_listed_package_must_be_declared(self):
        problem = deps.check(self.use(), {"python3-yaml"}, {})
        self.assertIn("<exec_depend>python3-yaml<", problem)
        self.assertIsNone(deps.check(self.use(), {"python3-yaml"},
                                     {"python3-yaml": {"exec_depend"}}))

    def test_test_depend_covers_tests_only(self):
        keys = {"python3-yaml": {"test_depend"}}
        self.assertIsNone(deps.check(self.use(test_only=True), {"python3-yaml"}, keys))
        self.assertIsNotNone(deps.check(self.use(test_only=False), {"python3-yaml"}, keys))

    def test_a_ros_package_is_declared_by_its_name(self):
        use = self.use("rospy")
        self.assertIn("<exec_depend>rospy<", deps.check(use, {"python3-rospy"}, {}))
        self.assertIsNone(deps.check(use, {"python3-rospy"}, {"rospy": {"depend"}}))

    def test_what_is_not_installed_fails(self):
        problem = deps.check(self.use("no_such_module_for_this_test"), set(), {})
        self.assertIn("is not installed", problem)
        problem = deps.check(deps.Use("command", "no-such-program-for-this-test", "x:1", False),
                             set(), {})
        self.assertIn("is not installed", problem)

    def test_required_packages_need_no_listing(self):
        self.assertIsNone(deps.check(deps.Use("command", "sed", "x:1", False), set(), {}))


def main():
    xunit = sys.argv[sys.argv.index("--xunit") + 1] if "--xunit" in sys.argv else None
    suite = unittest.defaultTestLoader.loadTestsFromModule(sys.modules[__name__])
    tests = list(_tests(suite))  # the runner lets go of them as it runs them
    result = unittest.TextTestRunner(verbosity=2).run(suite)
    if xunit:
        failed = {test.id(): text for test, text in result.failures + result.errors}
        root = ET.Element("testsuite", name="dependency_reading", tests=str(result.testsRun),
                          failures=str(len(failed)), errors="0")
        for test in tests:
            case = ET.SubElement(root, "testcase", classname=type(test).__name__,
                                 name=test.id().split(".")[-1])
            if test.id() in failed:
                ET.SubElement(case, "failure", message="failed").text = failed[test.id()]
        os.makedirs(os.path.dirname(os.path.abspath(xunit)), exist_ok=True)
        ET.ElementTree(root).write(xunit, encoding="utf-8", xml_declaration=True)
    return 0 if result.wasSuccessful() else 1


def _tests(suite):
    for item in suite:
        if isinstance(item, unittest.TestSuite):
            yield from _tests(item)
        else:
            yield item


if __name__ == "__main__":
    sys.exit(main())
