#!/usr/bin/python3
"""rostest: odometries in two frames no tf joins (test/rostest/enki_frames.test).

Within ~wall_deadline s the follower must log (WARN) that the two odometries are in different
frames, naming ~measurement_frame, and refuse the target's odometry for want of a transform,
naming ~measurement_frame and the transform to publish; and it must publish no tracking status
(it has no measurement: each robot's start pose is not taken as the same point).
"""

import os
import subprocess
import sys
import threading
import time
import unittest

import rospkg
import rospy
import rostest
from rosgraph_msgs.msg import Log

from projection_collision_avoidance.msg import FollowerStatus

import ros_test_helpers as helpers


class EnkiFrames(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.lines = []
        self.tracking = 0
        rospy.Subscriber("/follower/status", FollowerStatus, self.on_status, queue_size=100)
        self.follower = None
        self.bridge = None

    def tearDown(self):
        for process in (self.bridge, self.follower):
            if process is not None:
                process.terminate()
                process.wait(timeout=10)

    def start_follower(self, deadline):
        """follower_node as /follower/controller and, once its /rosout reaches the test, the
        bridge (parameters of both from the launch file)."""
        self.follower = subprocess.Popen(
            [helpers.node_executable("follower_node"), "__name:=controller", "__ns:=/follower",
             "odom:=/robot_1/odom", "target_odom:=/robot_0/odom"])
        self.log = rospy.Subscriber("/rosout", Log, self.on_log, queue_size=1000)
        while self.log.get_num_connections() == 0 and time.monotonic() < deadline:
            time.sleep(0.05)  # the follower's log reaches the test
        bridge = os.path.join(rospkg.RosPack().get_path(helpers.PACKAGE), "test", "enki",
                              "enki_bridge.py")
        self.bridge = subprocess.Popen([sys.executable, bridge, "__name:=enki"])

    def on_log(self, msg):
        if msg.name == "/follower/controller" and msg.level >= Log.WARN:
            with self.lock:
                self.lines.append(msg.msg)

    def on_status(self, status):
        with self.lock:
            if status.mode == FollowerStatus.MODE_TRACKING:
                self.tracking += 1

    def seen(self, *words):
        with self.lock:
            return any(all(w in line for w in words) for line in self.lines)

    def test_the_follower_names_the_missing_frame_parameter_and_transform(self):
        deadline = time.monotonic() + float(rospy.get_param("~wall_deadline"))
        self.start_follower(deadline)
        wanted = [("moved into the first with tf2", "~measurement_frame"),
                  ("no transform from", "~measurement_frame", "static transform",
                   "robot_0/odom")]
        while time.monotonic() < deadline and not all(self.seen(*w) for w in wanted):
            time.sleep(0.05)
        with self.lock:
            lines, tracking = list(self.lines), self.tracking
        for words in wanted:
            self.assertTrue(self.seen(*words), f"no WARN with {words}: {lines}")
        self.assertEqual(tracking, 0, "the follower tracked on odometries no tf joins")


if __name__ == "__main__":
    rospy.init_node("test_enki_frames")
    rostest.rosrun("projection_collision_avoidance", "enki_frames", EnkiFrames, sys.argv)
