#!/usr/bin/python3
"""rostest: the follower (and the plant and leader) refuse invalid parameters: each run exits
non-zero quickly with a message naming the parameter.

Each case loads the paper's Run 2 scenario into a fresh private namespace, spoils one entry,
starts the node there and waits (with a deadline) for it to exit."""

import os
import subprocess
import sys
import time
import unittest

import rospkg
import rospy
import rostest
import yaml

PACKAGE = "projection_collision_avoidance"
DEADLINE = 20.0  # wall seconds for a node to give up


def node_executable(name):
    """The node binary in the devel space or install space that rostest runs from."""
    for prefix in os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep):
        candidate = os.path.join(prefix, "lib", PACKAGE, name)
        if prefix and os.access(candidate, os.X_OK):
            return candidate
    raise RuntimeError(f"{name} not found under CMAKE_PREFIX_PATH")


def paper_scenario():
    path = os.path.join(rospkg.RosPack().get_path(PACKAGE), "config", "scenarios",
                        "paper_run2.yaml")
    with open(path) as stream:
        return yaml.safe_load(stream)


def set_in(tree, dotted, value):
    keys = dotted.split(".")
    for key in keys[:-1]:
        tree = tree.setdefault(key, {})
    tree[keys[-1]] = value


class InvalidParameters(unittest.TestCase):
    counter = 0

    def run_node(self, executable, scenario, options=None):
        """Runs a node under a fresh name with ~scenario and options; returns (code, output)."""
        InvalidParameters.counter += 1
        name = f"invalid_{InvalidParameters.counter}"
        if scenario is not None:
            rospy.set_param(f"/{name}/scenario", scenario)
        for key, value in (options or {}).items():
            rospy.set_param(f"/{name}/{key}", value)
        start = time.monotonic()
        process = subprocess.Popen([node_executable(executable), f"__name:={name}"],
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            output, _ = process.communicate(timeout=DEADLINE)
        except subprocess.TimeoutExpired:
            process.kill()
            output, _ = process.communicate()
            self.fail(f"{executable} still running after {DEADLINE} s:\n{output}")
        return process.returncode, output, time.monotonic() - start

    def expect_refused(self, key, change=None, options=None, executable="follower_node",
                       missing_scenario=False):
        scenario = None
        if not missing_scenario:
            scenario = paper_scenario()
            if change:
                change(scenario)
        code, output, seconds = self.run_node(executable, scenario, options)
        self.assertNotEqual(code, 0, f"exited 0:\n{output}")
        self.assertIn(key, output, f"the message does not name {key}:\n{output}")
        self.assertLess(seconds, DEADLINE)

    def test_missing_scenario(self):
        self.expect_refused("~scenario", missing_scenario=True)

    def test_missing_key(self):
        self.expect_refused("~scenario/controller/alpha",
                            lambda s: s["controller"].pop("alpha"))

    def test_wrong_type(self):
        self.expect_refused("~scenario/controller/epsilon",
                            lambda s: set_in(s, "controller.epsilon", "wide"))

    def test_out_of_range(self):
        self.expect_refused("~scenario/controller/alpha",
                            lambda s: set_in(s, "controller.alpha", 1.5))

    def test_not_hurwitz(self):
        self.expect_refused("~scenario/controller/tracker/gain",
                            lambda s: set_in(s, "controller.tracker.gain", [[-10.0, -5.0]]))

    def test_separation_not_in_kernel(self):
        self.expect_refused("~scenario/controller/separation",
                            lambda s: set_in(s, "controller.separation", [5.0, 1.0]))

    def test_wrong_size(self):
        self.expect_refused("~scenario/controller/estimator/gain",
                            lambda s: set_in(s, "controller.estimator.gain", [[-5.0, 0.0]]))

    def test_unknown_key(self):
        self.expect_refused("~scenario/controller/alfa",
                            lambda s: set_in(s, "controller.alfa", 0.2))

    def test_bad_node_option(self):
        self.expect_refused("~measurement_timeout", options={"measurement_timeout": -1.0})
        self.expect_refused("~marker_rate", options={"marker_rate": "fast"})

    def test_plant_and_leader_refuse_too(self):
        self.expect_refused("~scenario/controller/alpha",
                            lambda s: set_in(s, "controller.alpha", -0.5), executable="plant_node")
        self.expect_refused("~rate", options={"rate": -1.0}, executable="plant_node")
        self.expect_refused("~scenario/controller/alpha",
                            lambda s: set_in(s, "controller.alpha", -0.5),
                            executable="leader_node")


if __name__ == "__main__":
    rospy.init_node("test_invalid_parameters", anonymous=True)
    rostest.rosrun(PACKAGE, "invalid_parameters", InvalidParameters, sys.argv)
