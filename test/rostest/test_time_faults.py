#!/usr/bin/python3
"""rostest: time that jumps and a process that stalls, under a running follower.

~case "looping_bag": a bag of good measurements (3 s, 100 Hz) played with `rosbag play --loop
--clock`, so that ROS time goes back at every loop. Over ~loops loops the follower reports each
jump, never says its measurement is fresh with a negative age or tracks on one older than its
timeout, and tracks again after every jump.

~case "stall": the follower of pair.launch (Run 2, tracker on) is stopped with SIGSTOP for
~stall_s seconds and continued. After it resumes it publishes no fallback step (the measurements
were flowing all along), counts the stalled periods as missed, keeps tracking, and no two
consecutive commands differ by more than ~jerk_limit / ~control_rate (controller.jerk_limit).

~case "plant_stall": pair.launch on wall time; the plant is stopped with SIGSTOP for
~short_stall_s seconds, then, ~stall_gap_s seconds after it said so, for ~stall_s seconds. It
drops each backlog rather than catching up ticks stamped in the past, and says so: the report of
the long stall (at least 0.9 ~stall_s s behind) is not held back by the report of the short one
just before, which a plain 5-s throttle of the warning would swallow. It refuses no command as
stamped in the future, and the follower tracks again.

Parameters: ~wall_deadline (s) for each awaited condition, ~measurement_timeout (s)."""

import math
import os
import re
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import xmlrpc.client

import rosbag
import rospy
import rostest
from projection_collision_avoidance.msg import FollowerStatus, RelativeMeasurement
from rosgraph_msgs.msg import Log

import ros_test_helpers as helpers

PACKAGE = "projection_collision_avoidance"


class TimeFaults(unittest.TestCase):
    def setUp(self):
        self.deadline = rospy.get_param("~wall_deadline")
        self.timeout = rospy.get_param("~measurement_timeout")
        self.lock = threading.Lock()
        self.statuses = []
        rospy.Subscriber(rospy.get_param("~status_topic"), FollowerStatus, self.on_status)

    def on_status(self, msg):
        with self.lock:
            self.statuses.append((time.monotonic(), msg))

    def wait_for(self, condition, what):
        helpers.wait_for(self, condition, f"{what}", self.deadline)

    def latest(self):
        with self.lock:
            return self.statuses[-1][1] if self.statuses else None

    def assert_honest(self, statuses):
        for status in statuses:
            self.assertFalse(status.measurement_fresh and status.measurement_age < 0.0,
                             f"fresh with age {status.measurement_age}")
            if status.mode == FollowerStatus.MODE_TRACKING:
                self.assertLessEqual(status.measurement_age, self.timeout)
            self.assertTrue(all(math.isfinite(u) for u in status.command))

    def test_case(self):
        getattr(self, "check_" + rospy.get_param("~case"))()

    def check_looping_bag(self):
        start = 500.0
        with tempfile.TemporaryDirectory() as work:
            path = os.path.join(work, "measurements.bag")
            with rosbag.Bag(path, "w") as bag:
                for k in range(301):
                    stamp = rospy.Time.from_sec(start + 0.01 * k)
                    msg = RelativeMeasurement()
                    msg.header.stamp, msg.header.frame_id = stamp, "world"
                    msg.position, msg.velocity = [5.0], [0.0]
                    bag.write("/relative_measurement", msg, stamp)
            player = subprocess.Popen(["rosbag", "play", "--loop", "--clock", "--hz=200", "-q",
                                       path], stdout=subprocess.DEVNULL)
            try:
                loops = rospy.get_param("~loops")
                self.wait_for(lambda: self.latest() is not None and
                              self.latest().time_jumps >= loops, f"fewer than {loops} jumps")
            finally:
                player.send_signal(signal.SIGINT)
                player.wait(timeout=10)
        with self.lock:
            statuses = list(self.statuses)
        self.assert_honest([s for _, s in statuses])
        # After every jump back the follower tracks again.
        for jump in range(1, loops + 1):
            after = [s for _, s in statuses if s.time_jumps == jump]
            self.assertTrue(any(s.mode == FollowerStatus.MODE_TRACKING for s in after),
                            f"no tracking after jump {jump}")

    def stop_and_continue(self, node, seconds=None):
        """SIGSTOP to @p node for @p seconds (default ~stall_s), then SIGCONT; returns
        time.monotonic() at the end."""
        code, _, api = rospy.get_master().lookupNode(node)
        self.assertEqual(code, 1, f"{node} unknown to the master")
        pid = xmlrpc.client.ServerProxy(api).getPid(rospy.get_name())[2]
        os.kill(pid, signal.SIGSTOP)
        try:
            time.sleep(rospy.get_param("~stall_s") if seconds is None else seconds)
        finally:
            os.kill(pid, signal.SIGCONT)
        return time.monotonic()

    def check_plant_stall(self):
        node = rospy.get_param("~plant_node")
        lines = []
        rospy.Subscriber("/rosout", Log, lambda msg: lines.append((time.monotonic(), msg))
                         if msg.name == node else None)
        self.wait_for(lambda: self.latest() is not None and
                      self.latest().mode == FollowerStatus.MODE_TRACKING and
                      self.latest().ticks > 300, "the follower does not track")
        self.stop_and_continue(node, rospy.get_param("~short_stall_s"))
        self.wait_for(lambda: any("behind the wall clock" in m.msg for _, m in lines),
                      "the plant saying it dropped the backlog of the short stall")
        time.sleep(rospy.get_param("~stall_gap_s"))  # the long stall follows that report closely
        stalled = time.monotonic()
        resumed = self.stop_and_continue(node)
        self.wait_for(lambda: any(t > resumed for t, _ in self.statuses) and
                      [s for t, s in self.statuses if t > resumed][-1].mode ==
                      FollowerStatus.MODE_TRACKING, "tracking after the plant resumed")
        behind = re.compile(r"([0-9.eE+-]+) s behind the wall clock")
        least = 0.9 * rospy.get_param("~stall_s")
        self.wait_for(lambda: any(float(m_.group(1)) >= least for t, m in lines if t > stalled
                                  for m_ in [behind.search(m.msg)] if m_),
                      f"the plant saying it dropped a backlog of at least {least} s")
        # A second of tracking after the resume: a refusal would be logged by then.
        self.wait_for(lambda: sum(1 for t, s in self.statuses if t > resumed and
                                  s.mode == FollowerStatus.MODE_TRACKING) >=
                      rospy.get_param("~control_rate"), "a second of tracking after the resume")
        future = [m.msg for t, m in lines if t > stalled and
                  ("future stamp" in m.msg or "ahead of the clock" in m.msg)]
        self.assertFalse(future, f"the plant refused commands as stamped in the future: {future}")
        with self.lock:
            after = [s for t, s in self.statuses if t > resumed]
        self.assert_honest(after)

    def check_stall(self):
        node = rospy.get_param("~follower_node")
        self.wait_for(lambda: self.latest() is not None and
                      self.latest().mode == FollowerStatus.MODE_TRACKING and
                      self.latest().header.stamp.to_sec() > 5.0, "the follower does not track")
        code, _, api = rospy.get_master().lookupNode(node)
        self.assertEqual(code, 1, f"{node} unknown to the master")
        pid = xmlrpc.client.ServerProxy(api).getPid(rospy.get_name())[2]
        before = self.latest()
        os.kill(pid, signal.SIGSTOP)
        try:
            time.sleep(rospy.get_param("~stall_s"))
        finally:
            os.kill(pid, signal.SIGCONT)
        resumed = time.monotonic()
        # Watch 2 s of the follower's time after it resumed (its statuses carry their stamps).
        resume_stamp = before.header.stamp.to_sec() + rospy.get_param("~stall_s")
        self.wait_for(lambda: self.latest().header.stamp.to_sec() > resume_stamp + 2.0,
                      "2 s of statuses after the stall")
        with self.lock:
            after = [s for t, s in self.statuses if s.ticks > before.ticks]
        self.assertTrue(after, "no status after the stall")
        self.assert_honest(after)
        fallback = [s.header.stamp.to_sec() for s in after
                    if s.mode == FollowerStatus.MODE_MEASUREMENT_LOST]
        self.assertFalse(fallback, f"fallback steps after the stall at {fallback[:5]}")
        stalled_periods = rospy.get_param("~stall_s") * rospy.get_param("~control_rate")
        self.assertGreaterEqual(after[-1].missed_periods - before.missed_periods,
                                0.5 * stalled_periods)
        self.assertEqual(after[-1].mode, FollowerStatus.MODE_TRACKING)
        # Consecutive commands, the one before the stall included, differ by at most J T.
        max_change = rospy.get_param("~jerk_limit") / rospy.get_param("~control_rate")
        steps = [before] + after
        for previous, status in zip(steps, steps[1:]):
            change = math.sqrt(sum((a - b) ** 2 for a, b in zip(status.command, previous.command)))
            self.assertLessEqual(change, max_change + 1e-9,
                                 f"command jumps by {change} m/s^2 at tick {status.ticks}")
        self.assertLess(time.monotonic() - resumed, self.deadline)


if __name__ == "__main__":
    rospy.init_node("test_time_faults")
    rostest.rosrun(PACKAGE, "time_faults", TimeFaults, sys.argv)
