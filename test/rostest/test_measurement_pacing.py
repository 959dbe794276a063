#!/usr/bin/python3
"""rostest: a follower with ~trigger measurement behind a sender that repeats every measurement
(test/rostest/measurement_pacing.test) on the paper's Run 2. Asserts, from the follower's status
and commands up to ~end_time s of simulated time after the first status:

- max ||xi|| <= xi_max (the status's own bound): Run 2 stays inside;
- in every window of ~window s of ROS time (status stamps), the steps run (status.ticks) are at
  most ~control_rate * ~window + ~steps_tolerance: no sender steps the loop faster than the rate;
- over consecutive commands, ||u(k) - u(k-1)|| / (stamp(k) - stamp(k-1)) <= ~jerk_limit
  * (1 + ~jerk_tolerance): the jerk limit holds per second of the commands' stamps.

~wall_deadline: wall s to wait for the first status, and again for ~end_time to pass."""

import math
import sys
import threading
import unittest

import rospy
import rostest
from geometry_msgs.msg import AccelStamped
from projection_collision_avoidance.msg import FollowerStatus

import ros_test_helpers as helpers

PACKAGE = "projection_collision_avoidance"


class MeasurementPacingTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_measurement_pacing")
        cls.lock = threading.Lock()
        cls.statuses = []  # (stamp ns, ticks, xi_norm, xi_max)
        cls.commands = []  # (stamp ns, command)
        rospy.Subscriber("/follower/status", FollowerStatus, cls.on_status, queue_size=100000,
                         tcp_nodelay=True)
        rospy.Subscriber("/follower/command", AccelStamped, cls.on_command, queue_size=100000,
                         tcp_nodelay=True)

    @classmethod
    def on_status(cls, msg):
        with cls.lock:
            cls.statuses.append((msg.header.stamp.to_nsec(), msg.ticks, msg.xi_norm, msg.xi_max))

    @classmethod
    def on_command(cls, msg):
        a = msg.accel.linear
        with cls.lock:
            cls.commands.append((msg.header.stamp.to_nsec(), (a.x, a.y, a.z)))

    def param(self, name):
        self.assertTrue(rospy.has_param("~" + name), f"missing test parameter ~{name}")
        return float(rospy.get_param("~" + name))

    def test_the_loop_steps_at_the_control_rate_whatever_the_sender(self):
        deadline = self.param("wall_deadline")
        end_time = self.param("end_time")
        rate = self.param("control_rate")
        window = self.param("window")
        jerk_limit = self.param("jerk_limit")

        def first():
            with self.lock:
                return self.statuses[0][0] if self.statuses else None

        helpers.wait_for(self, lambda: first() is not None, "no status from the follower", deadline)
        begin_ns = first()
        end_ns = begin_ns + int(round(1e9 * end_time))

        def reached():
            with self.lock:
                return bool(self.statuses) and self.statuses[-1][0] >= end_ns

        helpers.wait_for(self, reached, f"simulated time never reached {end_time} s", deadline)
        with self.lock:
            statuses = [s for s in self.statuses if s[0] <= end_ns]
            commands = [c for c in self.commands if begin_ns <= c[0] <= end_ns]

        xi_max = statuses[-1][3]
        largest_xi = max(s[2] for s in statuses)
        # The most steps in any window of `window` s of ROS time (stamps in [t, t + window]).
        most_steps = 0
        begin = 0
        for end, (stamp, ticks, _, _) in enumerate(statuses):
            while stamp - statuses[begin][0] > int(round(1e9 * window)):
                begin += 1
            most_steps = max(most_steps, ticks - statuses[begin][1] + 1)
        jerk = 0.0
        for (t0, u0), (t1, u1) in zip(commands, commands[1:]):
            self.assertGreater(t1, t0, "two commands with one stamp, or out of order")
            change = math.sqrt(sum((b - a) ** 2 for a, b in zip(u0, u1)))
            jerk = max(jerk, change / (1e-9 * (t1 - t0)))
        overall = (statuses[-1][1] - statuses[0][1]) / (1e-9 * (statuses[-1][0] - statuses[0][0]))
        rospy.loginfo("measurement pacing: max ||xi|| %.3f m (xi_max %.3f m); most steps in %.1f s "
                      "of ROS time %d (%.1f steps/s over the run); max jerk %.3f m/s^3 over %d "
                      "commands", largest_xi, xi_max, window, most_steps, overall, jerk,
                      len(commands))
        print(f"max_xi={largest_xi:.4f} xi_max={xi_max:.4f} most_steps_per_window={most_steps} "
              f"steps_per_s={overall:.2f} max_jerk={jerk:.3f} commands={len(commands)}",
              file=sys.stderr)
        self.assertLessEqual(largest_xi, xi_max, "Run 2 left the bound xi_max")
        self.assertLessEqual(most_steps, rate * window + self.param("steps_tolerance"),
                             f"the follower stepped faster than {rate} Hz")
        self.assertGreater(len(commands), rate * end_time / 2, "too few commands observed")
        self.assertLessEqual(jerk, jerk_limit * (1.0 + self.param("jerk_tolerance")),
                             "the commands' jerk per second of their stamps passed jerk_limit")


if __name__ == "__main__":
    rostest.rosrun(PACKAGE, "test_measurement_pacing", MeasurementPacingTest, sys.argv)
