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
Parameters: ~seed, ~messages, ~wall_deadline, ~nodes.
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
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.on_diagnostics, queue_size=100)

    @classmethod
    def on_diagnostics(cls, msg):
        with cls.lock:
            for status in msg.status:  # named "<node>: <task>", the node's leading slash or not
                node = status.name.split(":")[0].lstrip("/")
                cls.diagnostics[node] = {v.key: v.value for v in status.values}

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
