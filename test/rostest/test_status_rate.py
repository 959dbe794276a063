#!/usr/bin/python3
"""rostest: the follower's ~status_rate (test/rostest/status_rate.test, on launch/pair.launch).

With control rate f and ~status_rate r, a status goes out every round(f / r) steps (its `ticks`
count), and at every change of mode: the fallback of a measurement outage is published at the
step it starts, not up to f / r steps later. Parameters: ~steps_per_status, ~outage_start (s),
~measurement_timeout (s), ~period (s), ~end_time (s), ~wall_deadline (s).
"""

import sys
import threading
import unittest

import rospy
import rostest
from projection_collision_avoidance.msg import FollowerStatus

import ros_test_helpers as helpers


class StatusRate(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.statuses = []
        rospy.Subscriber("/follower/status", FollowerStatus, self.keep)

    def keep(self, msg):
        with self.lock:
            self.statuses.append(msg)

    def test_statuses_every_n_steps_and_at_each_change_of_mode(self):
        end_time = rospy.get_param("~end_time")
        helpers.wait_for(
            self, lambda: self.statuses and self.statuses[-1].header.stamp.to_sec() >= end_time,
            "no status reached ~end_time", rospy.get_param("~wall_deadline"))
        n = rospy.get_param("~steps_per_status")
        with self.lock:
            statuses = list(self.statuses)
        self.assertLess(statuses[0].header.stamp.to_sec(), rospy.get_param("~outage_start"),
                        "the test joined after the outage began")
        previous = None
        regular = 0
        for status in statuses:
            if previous is not None:
                gap = status.ticks - previous.ticks
                if status.mode == previous.mode:
                    # Unchanged mode: only the regular statuses, steps 1, 1 + n, 1 + 2n, ...
                    self.assertEqual((status.ticks - 1) % n, 0, f"a status at step {status.ticks}")
                    self.assertLessEqual(gap, n)
                    regular += 1
                else:
                    self.assertLessEqual(gap, n)
            previous = status
        self.assertGreater(regular, 10)
        # The fallback is published at its first step: within the timeout and a period of the
        # outage's start.
        lost = [s for s in statuses if s.mode == FollowerStatus.MODE_MEASUREMENT_LOST]
        self.assertTrue(lost, "no fallback status during the outage")
        first = lost[0].header.stamp.to_sec()
        limit = rospy.get_param("~outage_start") + rospy.get_param("~measurement_timeout") + \
            2 * rospy.get_param("~period")
        self.assertLessEqual(first, limit, "the fallback was published late")
        self.assertNotEqual((lost[0].ticks - 1) % n, 0, "the test's outage should start off-grid")


if __name__ == "__main__":
    rospy.init_node("test_status_rate")
    rostest.rosrun("projection_collision_avoidance", "test_status_rate", StatusRate, sys.argv)
