#!/usr/bin/python3
"""rostest: the Enki pair on the bridge's own, bursty /clock (test/rostest/enki_bursty_clock.test).

The bridge advances /clock by its 100 ms physics step at once and publishes odometry at 100 Hz in
between, each stamped with the current clock (nine of ten repeat the stamp before). Within
~wall_deadline s the follower must publish ~min_statuses statuses in MODE_TRACKING and ROS time
reach ~min_ros_time s (past the leader's push), robot_1 must
move (ground truth at least ~min_travel m from its start) and the robots' centres never come closer
than ~min_centre_distance m. From the diagnostics, at the end: the follower's odometry input
refused at most ~max_rejected_odometry messages once it tracked (older stamps are superseded,
not refused), the
command adapter refused at most ~max_rejected_commands commands (none stamped ahead of its
lagging clock beyond its ~max_future_stamp) and accepted at least ~min_commands.
"""

import math
import sys
import threading
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from nav_msgs.msg import Odometry

from projection_collision_avoidance.msg import FollowerStatus

import ros_test_helpers as helpers


class EnkiBurstyClock(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.tracking = 0
        self.truth = {}
        self.start = {}
        self.min_distance = math.inf
        self.travel = 0.0
        self.follower = {}  # latest diagnostics values of the follower
        self.adapter = {}   # and of the command adapter
        rospy.Subscriber("/follower/status", FollowerStatus, self.on_status, queue_size=100)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=100)
        for robot in ("robot_0", "robot_1"):
            rospy.Subscriber(f"/{robot}/ground_truth", Odometry, self.on_truth, robot,
                             queue_size=100)

    def on_status(self, status):
        with self.lock:
            if status.mode == FollowerStatus.MODE_TRACKING:
                self.tracking += 1

    def on_diagnostics(self, msg):
        for status in msg.status:
            values = {v.key: v.value for v in status.values}
            with self.lock:
                if status.name.endswith("follower controller"):
                    self.follower = values
                elif status.name.endswith("command adapter"):
                    self.adapter = values

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
        """ros_test_helpers.wait_for with the condition read under the callbacks' lock."""
        def locked():
            with self.lock:
                return bool(condition())
        helpers.wait_for(self, locked, what, deadline)

    def test_follower_and_adapter_keep_up_with_a_bursty_clock(self):
        deadline = float(rospy.get_param("~wall_deadline"))
        min_statuses = int(rospy.get_param("~min_statuses"))
        min_centre = float(rospy.get_param("~min_centre_distance"))
        min_travel = float(rospy.get_param("~min_travel"))
        max_rejected_odometry = int(rospy.get_param("~max_rejected_odometry"))
        max_rejected_commands = int(rospy.get_param("~max_rejected_commands"))
        min_commands = int(rospy.get_param("~min_commands"))
        self.wait_for(lambda: self.tracking >= 10, deadline,
                      "the follower never tracks on the bursty clock")
        # Refusals from here on: before, the static transforms of the bridge may not have
        # arrived yet (refused for want of a transform, as they should be).
        with self.lock:
            self.follower = {}
        self.wait_for(lambda: self.follower, 10.0, "no diagnostics from the follower")
        with self.lock:
            start_rejected = int(self.follower["rejected_input_messages"])
        min_time = float(rospy.get_param("~min_ros_time"))
        self.wait_for(lambda: self.tracking >= min_statuses and rospy.get_time() >= min_time,
                      deadline, f"fewer than {min_statuses} tracking statuses by "
                      f"{min_time} s of ROS time")
        # The diagnostics of this moment or later (1 Hz of ROS time).
        with self.lock:
            self.follower, self.adapter = {}, {}
        self.wait_for(lambda: self.follower and self.adapter, 10.0,
                      "no diagnostics from the follower and the adapter")
        with self.lock:
            tracking, travel, distance = self.tracking, self.travel, self.min_distance
            follower, adapter = dict(self.follower), dict(self.adapter)
        rejected_odometry = int(follower["rejected_input_messages"]) - start_rejected
        superseded_odometry = int(follower["superseded_input_messages"])
        rejected_commands = int(adapter["rejected_commands"])
        accepted_commands = int(adapter["accepted_commands"])
        print("enki bursty clock: %d tracking statuses, robot_1 travelled %.3f m, closest centres "
              "%.3f m; follower odometry: %d refused, %d superseded, measurements refused %s; "
              "adapter: %d commands accepted, %d refused, odometry %s refused, %s superseded"
              % (tracking, travel, distance, rejected_odometry, superseded_odometry,
                 follower.get("rejected_measurements"), accepted_commands, rejected_commands,
                 adapter.get("rejected_odometry"), adapter.get("superseded_odometry")), flush=True)
        self.assertGreater(travel, min_travel, "robot_1 did not move: no cmd_vel reached it")
        self.assertGreater(distance, min_centre, "the robots came too close")
        self.assertLessEqual(rejected_odometry, max_rejected_odometry,
                             "the follower refused the bridge's odometry")
        self.assertLessEqual(rejected_commands, max_rejected_commands,
                             "the adapter refused the follower's commands: " +
                             adapter.get("rejected_commands", ""))
        self.assertGreaterEqual(accepted_commands, min_commands,
                                "the adapter converted too few commands")


if __name__ == "__main__":
    rospy.init_node("test_enki_bursty_clock")
    rostest.rosrun("projection_collision_avoidance", "enki_bursty_clock", EnkiBurstyClock,
                   sys.argv)
