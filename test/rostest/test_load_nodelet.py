#!/usr/bin/python3
"""rostest: load_nodelet asks a nodelet manager to load a nodelet and exits.

- A nodelet the manager can load: load_nodelet exits 0 within ~deadline s, and the manager
  publishes the nodelet's topics as the loader's remappings say (the leader's "leader/broadcast"
  remapped to /renamed_broadcast, the default name not at all).
- A type no plugin provides: load_nodelet exits 1 within ~deadline s and says the manager
  refused it, naming the type."""

import subprocess
import sys
import time
import unittest

import rosgraph
import rospy
from ros_test_helpers import node_executable

PKG = "projection_collision_avoidance"


def run_loader(*args):
    deadline = rospy.get_param("~deadline")
    return subprocess.run([node_executable("load_nodelet"), *args], capture_output=True, text=True,
                          timeout=deadline, check=False)


def publishers():
    """{topic: [publishing nodes]} from the master."""
    return dict(rosgraph.Master("/test_load_nodelet").getSystemState()[0])


class LoadNodelet(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_load_nodelet")
        rospy.wait_for_service("/manager/load_nodelet", timeout=rospy.get_param("~deadline"))

    def test_loads_with_name_and_remappings(self):
        done = run_loader(PKG + "/LeaderNodelet", "/manager", "__name:=loaded_leader",
                          "leader/broadcast:=/renamed_broadcast")
        self.assertEqual(done.returncode, 0, done.stderr)
        deadline = time.monotonic() + rospy.get_param("~deadline")
        while "/manager" not in publishers().get("/renamed_broadcast", []):
            self.assertLess(time.monotonic(), deadline, "the manager does not publish "
                            "/renamed_broadcast: %s" % publishers())
            time.sleep(0.1)
        self.assertNotIn("/leader/broadcast", publishers())

    def test_refused_type_exits_1(self):
        done = run_loader(PKG + "/NoSuchNodelet", "/manager", "__name:=not_loaded")
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("refused to load " + PKG + "/NoSuchNodelet", done.stderr)

    def test_usage(self):
        done = run_loader(PKG + "/LeaderNodelet")
        self.assertEqual(done.returncode, 2, done.stderr)
        self.assertIn("usage", done.stderr)


if __name__ == "__main__":
    import rostest
    rostest.rosrun(PKG, "load_nodelet", LoadNodelet, sys.argv)
