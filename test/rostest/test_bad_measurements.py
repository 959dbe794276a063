#!/usr/bin/python3
"""rostest: hand-written measurements and leader broadcasts, as a vehicle stack would send them,
to a lone follower: each malformed one is rejected and counted in the status, the command stays
finite and the follower keeps tracking. Parameters: ~wall_deadline (s) for each condition."""

import math
import sys
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import AccelStamped
from projection_collision_avoidance.msg import (FollowerStatus, LeaderBroadcast,
                                                RelativeMeasurement)

PACKAGE = "projection_collision_avoidance"


class BadMeasurements(unittest.TestCase):
    def setUp(self):
        self.status = None
        self.commands = []
        rospy.Subscriber("/status", FollowerStatus, self.on_status)
        rospy.Subscriber("/command", AccelStamped, self.on_command)
        self.publisher = rospy.Publisher("/relative_measurement", RelativeMeasurement,
                                         queue_size=10)
        self.leader_publisher = rospy.Publisher("/leader_broadcast", LeaderBroadcast,
                                                queue_size=10)
        self.deadline = rospy.get_param("~wall_deadline")

    def on_status(self, msg):
        self.status = msg

    def on_command(self, msg):
        self.commands.append(msg.accel.linear.x)

    def wait_for(self, condition):
        end = time.monotonic() + self.deadline
        while time.monotonic() < end and not rospy.is_shutdown():
            if condition():
                return True
            time.sleep(0.01)
        return condition()

    def send(self, position, velocity, frame="world", stamp_offset=0.0):
        msg = RelativeMeasurement()
        msg.header.stamp = rospy.Time.now() + rospy.Duration(stamp_offset)
        msg.header.frame_id = frame
        msg.position = position
        msg.velocity = velocity
        self.publisher.publish(msg)

    def send_broadcast(self, frame="world", stamp_offset=0.0, position=(0.0,), velocity=(0.0,),
                       leader_input=(0.0,), disturbance=()):
        msg = LeaderBroadcast()
        msg.header.stamp = rospy.Time.now() + rospy.Duration(stamp_offset)
        msg.header.frame_id = frame
        msg.position = list(position)
        msg.velocity = list(velocity)
        msg.input = list(leader_input)
        msg.disturbance = list(disturbance)
        self.leader_publisher.publish(msg)

    def rejected(self):
        return self.status.rejected_measurements if self.status else -1

    def rejected_broadcasts(self):
        return self.status.rejected_leader_broadcasts if self.status else -1

    def test_malformed_measurements_are_rejected_and_counted(self):
        self.assertTrue(self.wait_for(lambda: self.publisher.get_num_connections() > 0))
        self.send([5.0], [0.0])  # on the slot: x_1 - x_2 = d
        self.assertTrue(self.wait_for(lambda: self.status is not None), "no status")
        self.assertEqual(self.rejected(), 0)
        cases = [
            ("non-finite", dict(position=[math.nan], velocity=[0.0])),
            ("infinite", dict(position=[5.0], velocity=[math.inf])),
            ("wrong size", dict(position=[5.0, 1.0], velocity=[0.0, 0.0])),
            ("empty", dict(position=[], velocity=[])),
            ("wrong frame", dict(position=[5.0], velocity=[0.0], frame="map")),
            ("future stamp", dict(position=[5.0], velocity=[0.0], stamp_offset=10.0)),
            ("older than the last", dict(position=[5.0], velocity=[0.0], stamp_offset=-10.0)),
        ]
        for count, (name, fields) in enumerate(cases, start=1):
            self.send(**fields)
            self.assertTrue(self.wait_for(lambda c=count: self.rejected() == c),
                            f"{name}: rejected count {self.rejected()}, expected {count}")
        self.assertTrue(self.commands, "no command")
        self.assertTrue(all(math.isfinite(u) for u in self.commands))
        self.assertTrue(all(math.isfinite(x) for x in self.status.xi_hat))
        # A good measurement after all that is taken again.
        self.send([5.0], [0.0])
        self.assertTrue(self.wait_for(lambda: self.status.measurement_fresh))
        self.assertEqual(self.status.mode, FollowerStatus.MODE_TRACKING)

    def test_malformed_leader_broadcasts_are_rejected_and_counted(self):
        self.assertTrue(self.wait_for(lambda: self.publisher.get_num_connections() > 0))
        self.assertTrue(self.wait_for(lambda: self.leader_publisher.get_num_connections() > 0))
        self.send([5.0], [0.0])
        self.assertTrue(self.wait_for(lambda: self.status is not None), "no status")
        self.send_broadcast()
        self.assertTrue(self.wait_for(lambda: self.status.leader_fresh), "broadcast not taken")
        self.assertEqual(self.rejected_broadcasts(), 0)
        cases = [
            ("non-finite input", dict(leader_input=[math.nan])),
            ("infinite position", dict(position=[math.inf])),
            ("wrong input size", dict(leader_input=[0.0, 0.0])),
            ("empty velocity", dict(velocity=[])),
            ("wrong disturbance size", dict(disturbance=[0.0])),
            ("non-finite disturbance", dict(disturbance=[0.0, math.nan])),
            ("wrong frame", dict(frame="map")),
            ("future stamp", dict(stamp_offset=10.0)),
            ("older than the last", dict(stamp_offset=-10.0)),
        ]
        for count, (name, fields) in enumerate(cases, start=1):
            self.send([5.0], [0.0])  # keep the measurement fresh
            self.send_broadcast(**fields)
            self.assertTrue(self.wait_for(lambda c=count: self.rejected_broadcasts() == c),
                            f"{name}: rejected count {self.rejected_broadcasts()}, "
                            f"expected {count}")
        self.assertTrue(all(math.isfinite(u) for u in self.commands))
        self.assertEqual(self.rejected(), 0)


if __name__ == "__main__":
    rospy.init_node("test_bad_measurements")
    rostest.rosrun(PACKAGE, "bad_measurements", BadMeasurements, sys.argv)
