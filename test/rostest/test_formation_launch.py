#!/usr/bin/python3
"""rostest: formation.launch starts every follower of a formation, each once, with its own index
and links, also for N beyond roslaunch's recursion limit on one include per follower (~sizes,
up to ~large_size). Read from roslaunch itself (--nodes, --dump-params, --args), nothing run.

- For each N of ~sizes, with nodelets and without, and with link relays: exactly the nodes
  /follower_i/controller and /follower_i/link for i = 1..N, besides the world's.
- Follower i's ~formation_index and its link's ~receiver are i.
- In a chain of ~chain_size, follower i hears /follower_i/link_output, and its link relays
  /follower_(i-1)/broadcast (the leader's /leader/broadcast for i = 1)."""

import os
import re
import subprocess
import sys
import unittest

import rospkg
import rospy
import yaml

PKG = "projection_collision_avoidance"


def roslaunch(*args):
    """stdout of `roslaunch ARGS PKG formation.launch` (a failure fails the test)."""
    scenario = os.path.join(rospkg.RosPack().get_path(PKG), "config", "scenarios",
                            "paper_run2.yaml")
    done = subprocess.run(["roslaunch", *args, PKG, "formation.launch", "scenario:=" + scenario,
                           "rviz:=false"] + rospy.get_param("~launch_args", "").split(),
                          capture_output=True, text=True, timeout=rospy.get_param("~deadline"),
                          check=False)
    if done.returncode != 0:
        raise AssertionError("roslaunch %s failed: %s" % (" ".join(args), done.stderr[-2000:]))
    return done.stdout


class FormationLaunch(unittest.TestCase):
    def test_every_follower_once_for_each_size(self):
        sizes = [int(n) for n in str(rospy.get_param("~sizes")).split()]
        self.assertIn(rospy.get_param("~large_size"), sizes)
        for n in sizes:
            for nodelets in ("true", "false"):
                with self.subTest(n=n, nodelets=nodelets):
                    nodes = roslaunch("--nodes", "followers:=%d" % n, "nodelets:=" + nodelets,
                                      "link_relay:=true").split()
                    agents = sorted(x for x in nodes if x.startswith("/follower_"))
                    expected = sorted("/follower_%d/%s" % (i, part) for i in range(1, n + 1)
                                      for part in ("controller", "link"))
                    self.assertEqual(agents, expected)

    def test_each_follower_has_its_index(self):
        n = rospy.get_param("~chain_size")
        params = yaml.safe_load(roslaunch("--dump-params", "followers:=%d" % n,
                                          "link_relay:=true"))
        for i in range(1, n + 1):
            self.assertEqual(params["/follower_%d/controller/formation_index" % i], i)
            self.assertEqual(params["/follower_%d/link/receiver" % i], i)
        self.assertNotIn("/follower_%d/controller/formation_index" % (n + 1), params)

    def test_a_chain_links_each_follower_to_the_one_ahead(self):
        n = rospy.get_param("~chain_size")
        common = ("followers:=%d" % n, "topology:=chain", "shape:=line", "link_relay:=true")
        for i in range(1, n + 1):
            controller = roslaunch("--args", "/follower_%d/controller" % i, *common)
            link = roslaunch("--args", "/follower_%d/link" % i, *common)
            self.assertRegex(controller, r"leader_broadcast:=/follower_%d/link_output\b" % i)
            ahead = "/leader/broadcast" if i == 1 else "/follower_%d/broadcast" % (i - 1)
            self.assertRegex(link, r"input:=%s\b" % re.escape(ahead))
            self.assertRegex(link, r"output:=/follower_%d/link_output\b" % i)


if __name__ == "__main__":
    import rostest
    rospy.init_node("test_formation_launch")
    rostest.rosrun(PKG, "formation_launch", FormationLaunch, sys.argv)
