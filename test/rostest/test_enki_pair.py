#!/usr/bin/python3
"""rostest: the package's nodes driving a pair of Enki robots (test/rostest/enki_pair.test).

Within ~wall_deadline s the follower must publish ~min_statuses statuses in MODE_TRACKING, on
the bridge's odometry whose frames carry a leading slash (at 100 Hz, past the leader's push); over
that run: the adapter's
cmd_vel reaches robot_1 and it moves (its ground truth at least ~min_travel m from its start), and
the robots' centres (ground truth) never come closer than ~min_centre_distance m (two Thymios
touch at about 0.11 m).
"""

import math
import sys
import threading
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry

from projection_collision_avoidance.msg import FollowerStatus


class EnkiPair(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.tracking = 0
        self.truth = {}
        self.start = {}
        self.min_distance = math.inf
        self.travel = 0.0
        rospy.Subscriber("/follower/status", FollowerStatus, self.on_status, queue_size=100)
        for robot in ("robot_0", "robot_1"):
            rospy.Subscriber(f"/{robot}/ground_truth", Odometry, self.on_truth, robot,
                             queue_size=100)

    def on_status(self, status):
        with self.lock:
            if status.mode == FollowerStatus.MODE_TRACKING:
                self.tracking += 1

    def on_truth(self, msg, robot):
        p = msg.pose.pose.position
        with self.lock:
            self.truth[robot] = (p.x, p.y)
            self.start.setdefault(robot, (p.x, p.y))
            if len(self.truth) == 2:
                (x0, y0), (x1, y1) = self.truth["robot_0"], self.truth["robot_1"]
                self.min_distance = min(self.min_distance, math.hypot(x0 - x1, y0 - y1))
            if robot == "robot_1":
                sx, sy = self.start[robot]
                self.travel = max(self.travel, math.hypot(p.x - sx, p.y - sy))

    def wait_for(self, condition, deadline, what):
        end = time.monotonic() + deadline
        while time.monotonic() < end and not rospy.is_shutdown():
            with self.lock:
                if condition():
                    return
            time.sleep(0.05)
        self.fail(what)

    def test_follower_tracks_and_keeps_the_robots_apart(self):
        deadline = float(rospy.get_param("~wall_deadline", 60.0))
        min_statuses = int(rospy.get_param("~min_statuses", 2000))
        min_centre = float(rospy.get_param("~min_centre_distance", 0.12))
        min_travel = float(rospy.get_param("~min_travel", 0.1))
        self.wait_for(lambda: self.tracking >= 10, deadline,
                      "the follower never tracks: does it refuse the bridge's odometry?")
        self.wait_for(lambda: self.tracking >= min_statuses, deadline,
                      f"fewer than {min_statuses} tracking statuses")
        with self.lock:
            tracking, travel, distance = self.tracking, self.travel, self.min_distance
        print("enki pair: %d tracking statuses, robot_1 travelled %.3f m, closest "
              "centres %.3f m" % (tracking, travel, distance), flush=True)
        self.assertGreater(travel, min_travel, "robot_1 did not move: no cmd_vel reached it")
        self.assertGreater(distance, min_centre, "the robots came too close")


if __name__ == "__main__":
    rospy.init_node("test_enki_pair")
    rostest.rosrun("projection_collision_avoidance", "enki_pair", EnkiPair, sys.argv)
