#!/usr/bin/python3
"""rostest: odometry as some simulator bridges publish ground truth, the pose and twist in the
world under the robot's own frame (header.frame_id = child_frame_id), in
test/rostest/hostile_vehicle_inputs.test (after the hostile messages, on their master).

The group truth (a follower on ~input odometry with a time headway, a unicycle command adapter,
both with ~odometry/pose_frame world) must measure xi from the world poses, turn its own body
twist by the world yaw for the headway term, and drive along the robot's world heading; the group
truth_header (the same with the default ~odometry/pose_frame header) must refuse every such
message naming ~odometry/pose_frame (the follower's WARN and refusal counts, the adapter's
diagnostics), publish no status and never move its robot.
Parameters: ~truth_xi, ~truth_headway (the follower's xi and headway term), ~truth_speed (the
adapter's v), ~truth_tolerance, ~wall_deadline.
"""

import math
import sys
import threading
import time
import unittest

import rosgraph
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import AccelStamped, Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log

from projection_collision_avoidance.msg import FollowerStatus

import ros_test_helpers as helpers


def truth_odometry(frame, stamp, x, y, yaw, forward):
    """Ground truth as some bridges label it: header.frame_id @p frame (the robot's own),
    child_frame_id the same without its leading slash; the pose (x, y, yaw) in the world, a body
    twist @p forward along x (a unicycle's)."""
    msg = Odometry()
    msg.header.stamp, msg.header.frame_id, msg.child_frame_id = stamp, frame, frame.lstrip("/")
    msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
    msg.pose.pose.orientation.z = math.sin(yaw / 2)
    msg.pose.pose.orientation.w = math.cos(yaw / 2)
    msg.twist.twist.linear.x = forward
    return msg


class OdometryConventions(unittest.TestCase):
    def setUp(self):
        self.deadline = rospy.get_param("~wall_deadline")
        self.lock = threading.Lock()
        self.statuses, self.header_statuses = [], []
        self.twists, self.header_twists = [], []
        self.warnings = []  # WARN lines of /truth_header/controller
        self.diagnostics, self.summaries = {}, {}  # node -> {key: value}, its message
        pub = lambda topic, kind: rospy.Publisher(topic, kind, queue_size=100)  # noqa: E731
        self.own = pub("/hostile/truth_own_odom", Odometry)
        self.target = pub("/hostile/truth_target_odom", Odometry)
        self.adapter_odom = pub("/hostile/truth_adapter_odom", Odometry)
        self.command = pub("/hostile/truth_command", AccelStamped)
        rospy.Subscriber("/truth/status", FollowerStatus, self.keep(self.statuses))
        rospy.Subscriber("/truth_header/status", FollowerStatus, self.keep(self.header_statuses))
        rospy.Subscriber("/truth/cmd_vel", Twist, self.keep(self.twists))
        rospy.Subscriber("/truth_header/cmd_vel", Twist, self.keep(self.header_twists))
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=100)
        self.log = rospy.Subscriber("/rosout", Log, self.on_log, queue_size=1000)

    def keep(self, store):
        def callback(msg):
            with self.lock:
                store.append(msg)
        return callback

    def on_diagnostics(self, msg):
        with self.lock:
            for status in msg.status:  # named "<node>: <task>", the node's leading slash or not
                node = status.name.split(":")[0].lstrip("/")
                self.diagnostics[node] = {v.key: v.value for v in status.values}
                self.summaries[node] = status.message

    def on_log(self, msg):
        if msg.name == "/truth_header/controller" and msg.level >= Log.WARN:
            with self.lock:
                self.warnings.append(msg.msg)

    def wait_for(self, condition, what):
        helpers.wait_for(self, condition, what, self.deadline)

    def test_ground_truth_under_the_robots_own_frame(self):
        # The follower's refusals are logged once (the first of a kind): hear its log first.
        for publisher in (self.own, self.target, self.adapter_odom, self.command):
            self.wait_for(lambda p=publisher: p.get_num_connections() >= 2, f"{publisher.name}")
        uri = rosgraph.Master(rospy.get_name()).lookupNode("/truth_header/controller")
        self.wait_for(lambda: uri in [info[1] for info in self.log.impl.get_stats_info()],
                      "the follower's /rosout does not reach the test")
        tolerance = rospy.get_param("~truth_tolerance")
        want_xi, want_headway = rospy.get_param("~truth_xi"), rospy.get_param("~truth_headway")
        near = lambda got, want: len(got) == len(want) and all(  # noqa: E731
            abs(g - w) <= tolerance for g, w in zip(got, want))
        seen = []

        def measured():
            stamp = rospy.Time.now()  # one stamp: the pair needs no alignment
            self.target.publish(truth_odometry("robot_0", stamp, 6.3, 1.8, 0.0, 0.5))
            self.own.publish(truth_odometry("/robot_1/base_link", stamp, 1.0, 2.0, math.pi / 2,
                                            0.4))
            time.sleep(0.01)
            with self.lock:
                tracking = [s for s in self.statuses
                            if s.mode == FollowerStatus.MODE_TRACKING and s.own_state_fresh]
            seen[:] = [(list(s.xi), list(s.headway_command)) for s in tracking[-1:]]
            return any(near(s.xi, want_xi) and near(s.headway_command, want_headway)
                       for s in tracking)
        end = time.monotonic() + self.deadline
        while time.monotonic() < end and not measured():
            pass
        self.assertTrue(measured(), f"the follower with ~odometry/pose_frame world does not "
                                    f"measure xi {want_xi} with the headway term {want_headway}; "
                                    f"latest (xi, headway): {seen}")

        speed = rospy.get_param("~truth_speed")

        def headed():
            self.adapter_odom.publish(truth_odometry("robot_1", rospy.Time.now(), 0.0, 0.0,
                                                     math.pi / 2, 0.0))
            command = AccelStamped()
            command.header.stamp, command.header.frame_id = rospy.Time.now(), "world"
            command.accel.linear.y = 1.0  # along the robot's world heading
            self.command.publish(command)
            time.sleep(0.01)
            with self.lock:
                return any(abs(t.linear.x - speed) <= tolerance and abs(t.angular.z) <= tolerance
                           for t in self.twists)
        self.wait_for(headed, "the adapter with ~odometry/pose_frame world does not drive along "
                              "the robot's world heading")

        # The same messages, without ~odometry/pose_frame: refused, named, never used.
        def refused():
            with self.lock:
                named = [w for w in self.warnings if "~odometry/pose_frame" in w]
                follower = self.diagnostics.get("truth_header/controller", {})
                summary = self.summaries.get("truth_header/adapter", "")
            return (named and int(follower.get("rejected_input_messages", 0)) > 0 and
                    int(follower.get("rejected_odometry", 0)) > 0 and
                    "~odometry/pose_frame" in summary)
        self.wait_for(refused, "with ~odometry/pose_frame header, the follower (a WARN, its input "
                               "and headway odometry refusals) or the adapter (its diagnostics) "
                               "does not refuse the ground truth naming ~odometry/pose_frame")
        with self.lock:
            self.assertFalse(self.header_statuses, "the follower with ~odometry/pose_frame "
                                                   "header used ground truth under robot frames")
            self.assertFalse([t for t in self.header_twists if t.linear.x or t.angular.z],
                             "the adapter with ~odometry/pose_frame header moved its robot")


if __name__ == "__main__":
    rospy.init_node("test_odometry_conventions")
    rostest.rosrun("projection_collision_avoidance", "test_odometry_conventions",
                   OdometryConventions, sys.argv)
