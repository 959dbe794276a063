#!/usr/bin/python3
"""rostest: hostile messages at the vehicle adapters' inputs (test/rostest/hostile_vehicle_inputs.test).

Sends ~messages random messages to each of /hostile/own_odom and /hostile/target_odom (the
follower on odometry), /hostile/target_position and /hostile/target_pose (a follower on
positions), /hostile/command and /hostile/adapter_odom (the command adapter) and
/hostile/cmd_vel, /hostile/cmd_vel_stamped (a unicycle of the plant): stamps 0, now, far ahead,
far back, the largest ros::Time; frames empty, wrong, 100,000 characters long; values NaN,
infinite, huge, a zero quaternion. Then every node must answer a ping and do its job with good
messages: the followers track, the adapter converts a command, the plant drives the unicycle on
a Twist and on a TwistStamped (and refuses one stamped an hour ahead).
Odometry as some simulator bridges publish ground truth (pose and twist in the world under the
robot's own frame, header.frame_id = child_frame_id) goes to a follower and an adapter with
~odometry/pose_frame world, which must measure and head as the world poses say, and to a
follower and an adapter with the default, which must refuse it naming ~odometry/pose_frame.
Parameters: ~seed, ~messages, ~wall_deadline, ~nodes; ~truth_xi, ~truth_headway (the follower's
xi and headway term on the ground truth), ~truth_speed (the adapter's v), ~truth_tolerance.
"""

import math
import random
import sys
import threading
import time
import unittest

import rosnode
import rospy
import rostest
from geometry_msgs.msg import AccelStamped, PointStamped, PoseStamped, Twist, TwistStamped
from diagnostic_msgs.msg import DiagnosticArray
from rosgraph_msgs.msg import Log
from nav_msgs.msg import Odometry
from projection_collision_avoidance.msg import FollowerStatus

import ros_test_helpers as helpers

LATEST = (4294967295, 999999999)
VALUES = (0.0, 1.0, -2.5, 1e300, -1e300, float("nan"), float("inf"), float("-inf"), 5e-324)


class HostileVehicleInputs(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.seed = rospy.get_param("~seed")
        cls.rng = random.Random(cls.seed)
        cls.deadline = rospy.get_param("~wall_deadline")
        cls.lock = threading.Lock()
        cls.statuses = []
        cls.position_statuses = []
        cls.twists = []
        cls.plant_odometry = []
        pub = lambda topic, kind: rospy.Publisher(topic, kind, queue_size=10000)  # noqa: E731
        cls.own = pub("/hostile/own_odom", Odometry)
        cls.target = pub("/hostile/target_odom", Odometry)
        cls.command = pub("/hostile/command", AccelStamped)
        cls.adapter_odom = pub("/hostile/adapter_odom", Odometry)
        cls.cmd_vel = pub("/hostile/cmd_vel", Twist)
        cls.cmd_vel_stamped = pub("/hostile/cmd_vel_stamped", TwistStamped)
        cls.target_position = pub("/hostile/target_position", PointStamped)
        cls.target_pose = pub("/hostile/target_pose", PoseStamped)
        rospy.Subscriber("/position_follower/status", FollowerStatus,
                         cls.keep(cls.position_statuses))
        rospy.Subscriber("/follower/status", FollowerStatus, cls.keep(cls.statuses))
        rospy.Subscriber("/adapter/cmd_vel", Twist, cls.keep(cls.twists))
        rospy.Subscriber("/follower/odom", Odometry, cls.keep(cls.plant_odometry))
        cls.diagnostics = {}  # status name -> {key: value}, the latest
        cls.summaries = {}  # status name -> its message, the latest
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.on_diagnostics, queue_size=100)
        # Ground truth under the robots' own frames (group truth: ~odometry/pose_frame world;
        # truth_header: the default).
        cls.truth_own = pub("/hostile/truth_own_odom", Odometry)
        cls.truth_target = pub("/hostile/truth_target_odom", Odometry)
        cls.truth_adapter_odom = pub("/hostile/truth_adapter_odom", Odometry)
        cls.truth_command = pub("/hostile/truth_command", AccelStamped)
        cls.truth_statuses, cls.header_statuses = [], []
        cls.truth_twists, cls.header_twists = [], []
        cls.header_warnings = []
        rospy.Subscriber("/truth/status", FollowerStatus, cls.keep(cls.truth_statuses))
        rospy.Subscriber("/truth_header/status", FollowerStatus, cls.keep(cls.header_statuses))
        rospy.Subscriber("/truth/cmd_vel", Twist, cls.keep(cls.truth_twists))
        rospy.Subscriber("/truth_header/cmd_vel", Twist, cls.keep(cls.header_twists))
        rospy.Subscriber("/rosout", Log, cls.on_log, queue_size=1000)

    @classmethod
    def on_diagnostics(cls, msg):
        with cls.lock:
            for status in msg.status:  # named "<node>: <task>", the node's leading slash or not
                node = status.name.split(":")[0].lstrip("/")
                cls.diagnostics[node] = {v.key: v.value for v in status.values}
                cls.summaries[node] = status.message

    @classmethod
    def on_log(cls, msg):
        if msg.name == "/truth_header/controller" and msg.level >= Log.WARN:
            with cls.lock:
                cls.header_warnings.append(msg.msg)

    def counts(self):
        """(follower's rejected and superseded odometry, adapter's), from the latest
        diagnostics; None before both were heard."""
        with self.lock:
            follower = self.diagnostics.get("follower/controller")
            adapter = self.diagnostics.get("follower/adapter")
        if follower is None or adapter is None:
            return None
        return (int(follower["rejected_input_messages"]),
                int(follower["superseded_input_messages"]),
                int(adapter["rejected_odometry"]), int(adapter["superseded_odometry"]))

    @classmethod
    def keep(cls, store):
        def callback(msg):
            with cls.lock:
                store.append(msg)
        return callback

    def wait_for(self, condition, what):
        helpers.wait_for(self, condition, f"{what} (seed {self.seed})", self.deadline)

    def value(self):
        return self.rng.choice(VALUES)

    def stamp(self):
        now = rospy.Time.now()
        return self.rng.choice((rospy.Time(0), now, now + rospy.Duration(5),
                                rospy.Time(max(0.0, now.to_sec() - 5)), rospy.Time(*LATEST),
                                rospy.Time(self.rng.uniform(0, 4294967295))))

    def frame(self):
        return self.rng.choice(("world", "", "follower", "nowhere", "x" * 100000))

    def odometry(self):
        msg = Odometry()
        msg.header.stamp, msg.header.frame_id = self.stamp(), self.frame()
        msg.child_frame_id = self.frame()
        p, q, v, w = msg.pose.pose.position, msg.pose.pose.orientation, msg.twist.twist.linear, \
            msg.twist.twist.angular
        p.x, p.y, p.z = self.value(), self.value(), self.value()
        q.x, q.y, q.z, q.w = self.rng.choice(((0, 0, 0, 0), (0, 0, 0, 1), (self.value(),) * 4))
        v.x, v.y, v.z = self.value(), self.value(), self.value()
        w.x, w.y, w.z = self.value(), self.value(), self.value()
        return msg

    def point(self, point):
        point.x, point.y, point.z = self.value(), self.value(), self.value()

    def twist(self):
        msg = Twist()
        msg.linear.x, msg.linear.y, msg.angular.z = self.value(), self.value(), self.value()
        return msg

    def good_odometry(self, x, yaw):
        msg = Odometry()
        msg.header.stamp, msg.header.frame_id, msg.child_frame_id = rospy.Time.now(), "world", "b"
        msg.pose.pose.position.x = x
        msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        return msg

    def test_every_node_survives_and_works_after(self):
        publishers = (self.own, self.target, self.command, self.adapter_odom, self.cmd_vel,
                      self.cmd_vel_stamped, self.target_position, self.target_pose)
        for publisher in publishers:
            self.wait_for(lambda p=publisher: p.get_num_connections() > 0, f"{publisher.name}")
        for _ in range(rospy.get_param("~messages")):
            self.own.publish(self.odometry())
            self.target.publish(self.odometry())
            self.adapter_odom.publish(self.odometry())
            command = AccelStamped()
            command.header.stamp, command.header.frame_id = self.stamp(), self.frame()
            command.accel.linear.x, command.accel.linear.y = self.value(), self.value()
            command.accel.linear.z = self.rng.choice((0.0, self.value()))
            self.command.publish(command)
            self.cmd_vel.publish(self.twist())
            stamped = TwistStamped()
            stamped.header.stamp, stamped.header.frame_id = self.stamp(), self.frame()
            stamped.twist = self.twist()
            self.cmd_vel_stamped.publish(stamped)
            position = PointStamped()
            position.header.stamp, position.header.frame_id = self.stamp(), self.frame()
            self.point(position.point)
            self.target_position.publish(position)
            pose = PoseStamped()
            pose.header.stamp, pose.header.frame_id = self.stamp(), self.frame()
            self.point(pose.pose.position)
            self.target_pose.publish(pose)
            time.sleep(0.002)
        for node in rospy.get_param("~nodes"):
            self.assertTrue(rosnode.rosnode_ping(node, max_count=1, verbose=False),
                            f"{node} is gone (seed {self.seed})")
        # The follower tracks on good odometry: the target 5 m ahead along x.
        with self.lock:
            del self.statuses[:]
        def tracking():
            self.target.publish(self.good_odometry(5.0, 0.0))
            self.own.publish(self.good_odometry(0.0, 0.0))
            with self.lock:
                return any(s.mode == FollowerStatus.MODE_TRACKING and
                           all(math.isfinite(x) for x in s.command) for s in self.statuses)
        self.wait_for(tracking, "the follower does not track on good odometry")
        # The follower on positions tracks on good positions: the target 5 m ahead along x.
        with self.lock:
            del self.position_statuses[:]
        def tracking_on_positions():
            position = PointStamped()
            position.header.stamp, position.header.frame_id = rospy.Time.now(), "world"
            position.point.x = 5.0
            self.target_position.publish(position)
            time.sleep(0.01)
            with self.lock:
                return any(s.mode == FollowerStatus.MODE_TRACKING and
                           all(math.isfinite(x) for x in s.command) and
                           abs(s.xi[0]) < 0.5 for s in self.position_statuses)
        self.wait_for(tracking_on_positions, "the follower does not track on good positions")
        # The adapter turns a good command into a finite (v, omega).
        with self.lock:
            del self.twists[:]
        def converted():
            self.adapter_odom.publish(self.good_odometry(0.0, 0.3))
            command = AccelStamped()
            command.header.stamp, command.header.frame_id = rospy.Time.now(), "world"
            command.accel.linear.x = 1.0
            self.command.publish(command)
            with self.lock:
                return any(t.linear.x > 0.0 and math.isfinite(t.angular.z) for t in self.twists)
        self.wait_for(converted, "the adapter does not convert a good command")
        # The plant drives the unicycle on a good Twist: finite odometry, moving forward.
        def driven():
            twist = Twist()
            twist.linear.x = 0.5
            self.cmd_vel.publish(twist)
            with self.lock:
                recent = self.plant_odometry[-5:]
            return len(recent) == 5 and all(math.isfinite(o.pose.pose.position.x) for o in recent) \
                and recent[-1].twist.twist.linear.x > 0.1
        self.wait_for(driven, "the plant does not drive the unicycle on a good Twist")
        # A TwistStamped stamped now drives it too, and one stamped an hour ahead after it is
        # refused by its header (the speed settles at the first one's).
        def driven_stamped():
            now = TwistStamped()
            now.header.stamp = rospy.Time.now()
            now.twist.linear.x = 0.25
            self.cmd_vel_stamped.publish(now)
            ahead = TwistStamped()
            ahead.header.stamp = now.header.stamp + rospy.Duration(3600.0)
            ahead.twist.linear.x = 0.05
            self.cmd_vel_stamped.publish(ahead)
            with self.lock:
                recent = self.plant_odometry[-5:]
            return len(recent) == 5 and all(abs(o.twist.twist.linear.x - 0.25) < 0.02
                                            for o in recent)
        self.wait_for(driven_stamped, "the plant does not hold a good TwistStamped and refuse one "
                                      "stamped ahead")


    @staticmethod
    def truth_odometry(frame, stamp, x, y, yaw, forward):
        """Ground truth as some bridges label it: header.frame_id @p frame (the robot's own),
        child_frame_id the same without its leading slash; the pose (x, y, yaw) in the world, a
        body twist @p forward along x (a unicycle's)."""
        msg = Odometry()
        msg.header.stamp, msg.header.frame_id, msg.child_frame_id = stamp, frame, frame.lstrip("/")
        msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
        msg.pose.pose.orientation.z = math.sin(yaw / 2)
        msg.pose.pose.orientation.w = math.cos(yaw / 2)
        msg.twist.twist.linear.x = forward
        return msg

    def test_ground_truth_under_the_robots_own_frame(self):
        """With ~odometry/pose_frame world the follower measures xi from the world poses, its
        time headway turns the body twist by the world yaw, and the adapter heads by it; with
        the default both refuse the messages naming ~odometry/pose_frame."""
        for publisher in (self.truth_own, self.truth_target, self.truth_adapter_odom,
                          self.truth_command):
            self.wait_for(lambda p=publisher: p.get_num_connections() >= 2, f"{publisher.name}")
        tolerance = rospy.get_param("~truth_tolerance")
        want_xi, want_headway = rospy.get_param("~truth_xi"), rospy.get_param("~truth_headway")
        near = lambda got, want: len(got) == len(want) and all(  # noqa: E731
            abs(g - w) <= tolerance for g, w in zip(got, want))
        seen = []

        def measured():
            stamp = rospy.Time.now()  # one stamp: the pair needs no alignment
            self.truth_target.publish(self.truth_odometry("robot_0", stamp, 6.3, 1.8, 0.0, 0.5))
            self.truth_own.publish(self.truth_odometry("/robot_1/base_link", stamp, 1.0, 2.0,
                                                       math.pi / 2, 0.4))
            time.sleep(0.01)
            with self.lock:
                tracking = [s for s in self.truth_statuses
                            if s.mode == FollowerStatus.MODE_TRACKING and s.own_state_fresh]
            seen[:] = [(list(s.xi), list(s.headway_command)) for s in tracking[-1:]]
            return any(near(s.xi, want_xi) and near(s.headway_command, want_headway)
                       for s in tracking)
        end = time.monotonic() + self.deadline
        while time.monotonic() < end and not measured():
            pass
        self.assertTrue(measured(), f"the follower on ground truth with ~odometry/pose_frame "
                                    f"world does not measure xi {want_xi} with the headway term "
                                    f"{want_headway}; latest (xi, headway): {seen}")

        speed = rospy.get_param("~truth_speed")
        def headed():
            odometry = self.truth_odometry("robot_1", rospy.Time.now(), 0.0, 0.0, math.pi / 2, 0.0)
            self.truth_adapter_odom.publish(odometry)
            command = AccelStamped()
            command.header.stamp, command.header.frame_id = rospy.Time.now(), "world"
            command.accel.linear.y = 1.0
            self.truth_command.publish(command)
            time.sleep(0.01)
            with self.lock:
                return any(abs(t.linear.x - speed) <= tolerance and abs(t.angular.z) <= tolerance
                           for t in self.truth_twists)
        self.wait_for(headed, "the adapter on ground truth with ~odometry/pose_frame world does "
                              "not drive along its world heading")

        # The same messages, without ~odometry/pose_frame: refused, named, never used.
        def refused():
            with self.lock:
                warnings = [w for w in self.header_warnings if "~odometry/pose_frame" in w]
                follower = self.diagnostics.get("truth_header/controller", {})
                summary = self.summaries.get("truth_header/adapter", "")
            return (warnings and int(follower.get("rejected_input_messages", 0)) > 0 and
                    int(follower.get("rejected_odometry", 0)) > 0 and
                    "~odometry/pose_frame" in summary)
        self.wait_for(refused, "the follower (WARN, input and headway odometry counts) or the "
                               "adapter (diagnostics) with ~odometry/pose_frame header does not "
                               "refuse ground truth under the robot's frame naming the parameter")
        with self.lock:
            self.assertFalse(self.header_statuses, "the follower with ~odometry/pose_frame "
                                                   "header used ground truth under robot frames")
            self.assertFalse([t for t in self.header_twists if t.linear.x or t.angular.z],
                             "the adapter with ~odometry/pose_frame header moved its robot")

    def test_reordered_odometry_is_superseded_not_refused(self):
        """Good odometry on the follower's two topics and the adapter's, every message sent
        again 5 ms earlier after it and once more as it was (a bridge publishing from two
        threads, a clock standing still): nothing refused, two superseded per message."""
        self.wait_for(lambda: self.counts() is not None, "no diagnostics of follower and adapter")
        # The counts once the earlier test's messages are all judged: two diagnostics (1 Hz)
        # alike.
        seen = [self.counts()]
        def settled():
            time.sleep(1.5)
            seen.append(self.counts())
            return seen[-1] == seen[-2]
        self.wait_for(settled, "the counts do not settle")
        before = seen[-1]
        pairs = 100
        for _ in range(pairs):
            now = rospy.Time.now()
            for publisher, x in ((self.target, 5.0), (self.own, 0.0), (self.adapter_odom, 0.0)):
                newer = self.good_odometry(x, 0.0)
                newer.header.stamp = now
                older = self.good_odometry(x, 0.0)
                older.header.stamp = now - rospy.Duration(0.005)
                for msg in (newer, older, newer):
                    publisher.publish(msg)
            time.sleep(0.01)
        expected = (0, 2 * 2 * pairs, 0, 2 * pairs)
        def counted():
            after = self.counts()
            return after is not None and after[1] - before[1] >= expected[1] and \
                after[3] - before[3] >= expected[3]
        self.wait_for(counted, "the reordered odometry is not counted as superseded")
        after = self.counts()
        self.assertEqual([a - b for a, b in zip(after, before)], list(expected),
                         "(follower refused, superseded; adapter refused, superseded)")

if __name__ == "__main__":
    rospy.init_node("test_hostile_vehicle_inputs")
    rostest.rosrun("projection_collision_avoidance", "test_hostile_vehicle_inputs",
                   HostileVehicleInputs, sys.argv)
