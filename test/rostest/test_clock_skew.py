#!/usr/bin/python3
"""rostest: a follower whose measurement sender's clock is off by ~skew seconds
(test/rostest/clock_skew.test). This test plays the sender: RelativeMeasurements of the follower at
its slot, at 100 Hz, stamped with its own clock plus ~skew. With ~expect_tracking the follower
must track on them (and report the skew); without, it must refuse or age them all and brake.
Parameters: ~skew (s), ~expect_tracking, ~skew_tolerance (s), ~wall_deadline (s).
"""

import math
import sys
import threading
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from projection_collision_avoidance.msg import FollowerStatus, RelativeMeasurement

import ros_test_helpers as helpers


class ClockSkew(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.statuses = []
        self.rejected = 0
        rospy.Subscriber("/follower/status", FollowerStatus, self.keep)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.diagnostics)
        self.publisher = rospy.Publisher("/follower/relative_measurement", RelativeMeasurement,
                                         queue_size=10)
        self.skew = rospy.Duration.from_sec(rospy.get_param("~skew"))
        self.running = True
        self.sender = threading.Thread(target=self.send, daemon=True)
        self.sender.start()

    def tearDown(self):
        self.running = False
        self.sender.join()

    def keep(self, msg):
        with self.lock:
            self.statuses.append(msg)

    def diagnostics(self, msg):
        for status in msg.status:
            for entry in status.values:
                if entry.key == "rejected_measurements":
                    with self.lock:
                        self.rejected = int(entry.value)

    def send(self):
        while self.running and not rospy.is_shutdown():
            msg = RelativeMeasurement()
            msg.header.stamp = rospy.Time.now() + self.skew
            msg.position, msg.velocity = [5.0], [0.0]  # at its slot: d = [5, 0]
            self.publisher.publish(msg)
            time.sleep(0.01)

    def test_the_follower_on_a_skewed_sender(self):
        deadline = rospy.get_param("~wall_deadline")
        if rospy.get_param("~expect_tracking"):
            def tracking():
                with self.lock:
                    recent = self.statuses[-50:]
                return len(recent) == 50 and all(
                    s.mode == FollowerStatus.MODE_TRACKING for s in recent)
            helpers.wait_for(self, tracking, "the follower does not track", deadline)
            with self.lock:
                last = self.statuses[-1]
            # receipt - stamp = -skew plus the delay
            self.assertAlmostEqual(last.measurement_skew, -self.skew.to_sec(),
                                   delta=rospy.get_param("~skew_tolerance"))
            self.assertLess(last.measurement_age, 0.1)
        else:
            # Seen in the diagnostics: no status is published before a measurement is accepted.
            helpers.wait_for(self, lambda: self.rejected >= 100,
                             "the follower does not refuse the measurements", deadline)
            with self.lock:
                tracked = [s for s in self.statuses if s.mode == FollowerStatus.MODE_TRACKING]
            self.assertFalse(tracked, "tracked on measurements it should not trust")


if __name__ == "__main__":
    rospy.init_node("test_clock_skew")
    rostest.rosrun("projection_collision_avoidance", "test_clock_skew", ClockSkew, sys.argv)
