#!/usr/bin/python3
"""rostest: the `neighbours` input of a follower with formation.neighbours (doc/boundary.md), fed
by the test as a third-party sender would: the first step waits for an array; each malformed
array, a repeated stamp (a duplicating sender) and a second publisher's array are refused whole
and counted; a stale one brakes the follower until a fresh one comes; an agent closing in binds
the command; a flood of the largest arrays and one far too large leave
the node running. Parameters: ~wall_deadline (s) per condition, ~measurement_timeout (s, the
follower's), ~flood_messages and ~flood_entries (the flood), ~oversized_entries."""

import math
import subprocess
import sys
import threading
import unittest

import rospy
import rostest
from projection_collision_avoidance.msg import (FollowerStatus, Neighbour, NeighbourArray,
                                                RelativeMeasurement)
from ros_test_helpers import PACKAGE, wait_for

SLOT = [4.330127018922194, 2.5]  # d_1: follower 1's slot on the V's arm, 30 degrees off x


def entry(name, position, velocity=(0.0, 0.0)):
    neighbour = Neighbour()
    neighbour.id = name
    neighbour.position = list(position)
    neighbour.velocity = list(velocity)
    return neighbour


def calm_crowd():
    """The leader on the slot and the V's other followers on theirs, relative to follower 1."""
    return [entry("leader", SLOT), entry("follower_2", [0.0, 5.0]),
            entry("follower_3", [-4.33, -2.5]), entry("follower_4", [-4.33, 7.5])]


class BadNeighbours(unittest.TestCase):
    def setUp(self):
        self.status = None
        self.lock = threading.Lock()
        self.deadline = rospy.get_param("~wall_deadline")
        self.timeout = rospy.get_param("~measurement_timeout")
        rospy.Subscriber("/follower_1/status", FollowerStatus, self.on_status)
        self.measurements = rospy.Publisher("/follower_1/relative_measurement",
                                            RelativeMeasurement, queue_size=10)
        self.neighbours = rospy.Publisher("/follower_1/neighbours", NeighbourArray,
                                          queue_size=1000)
        wait_for(self, lambda: self.measurements.get_num_connections() > 0
                 and self.neighbours.get_num_connections() > 0, "the follower never subscribed",
                 self.deadline)
        # The relative measurement stays fresh throughout (50 Hz).
        self.timer = rospy.Timer(rospy.Duration(0.02), lambda _: self.send_measurement())

    def tearDown(self):
        self.timer.shutdown()

    def on_status(self, msg):
        with self.lock:
            self.status = msg

    def latest(self):
        with self.lock:
            return self.status

    def send_measurement(self):
        msg = RelativeMeasurement()
        msg.header.stamp = rospy.Time.now()
        msg.header.frame_id = "world"
        msg.position = list(SLOT)
        msg.velocity = [0.0, 0.0]
        self.measurements.publish(msg)

    def send(self, entries, frame="world", stamp_offset=0.0, stamp=None):
        msg = NeighbourArray()
        msg.header.stamp = stamp if stamp is not None else rospy.Time.now() + rospy.Duration(
            stamp_offset)
        msg.header.frame_id = frame
        msg.neighbours = entries
        self.neighbours.publish(msg)
        return msg.header.stamp

    def rejected(self):
        status = self.latest()
        return status.rejected_neighbours if status else -1

    def wait(self, condition, what):
        wait_for(self, lambda: self.latest() is not None and condition(self.latest()), what,
                 self.deadline)

    def test_1_the_first_step_waits_and_each_bad_array_is_refused(self):
        # No status before the first array: the first step waits for one.
        rospy.sleep(0.3)
        self.assertIsNone(self.latest(), "a step ran before any neighbour array")
        accepted = self.send(calm_crowd())
        self.wait(lambda s: s.mode == FollowerStatus.MODE_TRACKING and s.neighbours_fresh,
                  "not tracking with a fresh array")
        status = self.latest()
        self.assertTrue(status.neighbours_configured)
        self.assertEqual(status.neighbours_sent, 4)
        self.assertEqual(status.rejected_neighbours, 0)

        cases = [
            ("non-finite position", [entry("follower_2", [math.nan, 0.0])]),
            ("infinite velocity", [entry("follower_2", [0.0, 5.0], [0.0, math.inf])]),
            ("huge finite position", [entry("follower_2", [1e200, 1e200])]),
            ("one axis", [entry("follower_2", [0.0])]),
            ("three axes", [entry("follower_2", [0.0, 5.0, 0.0], [0.0, 0.0, 0.0])]),
            ("no velocity", [entry("follower_2", [0.0, 5.0], [])]),
            ("itself", [entry("follower_1", [0.0, 0.0])]),
        ]
        for count, (name, entries) in enumerate(cases, start=1):
            self.send(calm_crowd() + entries)
            self.wait(lambda s, c=count: s.rejected_neighbours == c,
                      f"{name}: rejected {self.rejected()}, expected {count}")
        header_cases = [
            ("wrong frame", dict(frame="map")),
            ("zero stamp", dict(stamp=rospy.Time(0))),
            ("future stamp", dict(stamp_offset=10.0)),
            ("older than the last", dict(stamp=accepted - rospy.Duration(0.001))),
            ("repeated stamp (a duplicating sender)", dict(stamp=accepted)),
        ]
        for count, (name, fields) in enumerate(header_cases, start=len(cases) + 1):
            self.send(calm_crowd(), **fields)
            self.wait(lambda s, c=count: s.rejected_neighbours == c,
                      f"{name}: rejected {self.rejected()}, expected {count}")
        self.assertTrue(all(math.isfinite(u) for u in self.latest().command))
        # A second publisher (another node) while this one holds the input: refused and counted.
        count = len(cases) + len(header_cases) + 1
        subprocess.run(["rostopic", "pub", "-1", "/follower_1/neighbours",
                        "projection_collision_avoidance/NeighbourArray",
                        "{header: {stamp: now, frame_id: world}, neighbours: []}"],
                       check=True, timeout=self.deadline, stdout=subprocess.DEVNULL)
        self.wait(lambda s: s.rejected_neighbours == count,
                  f"second publisher: rejected {self.rejected()}, expected {count}")

        # Refused arrays leave the last accepted one, which goes stale: the follower brakes.
        self.wait(lambda s: s.mode == FollowerStatus.MODE_MEASUREMENT_LOST
                  and not s.neighbours_fresh and s.fallback, "a stale array did not brake")
        self.assertGreater(self.latest().neighbours_age, self.timeout)
        self.send(calm_crowd())
        self.wait(lambda s: s.mode == FollowerStatus.MODE_TRACKING and s.neighbours_fresh,
                  "a fresh array after the stale one did not resume tracking")

    def test_2_an_agent_closing_in_binds_the_command(self):
        self.send(calm_crowd())
        self.wait(lambda s: s.neighbours_fresh, "no fresh array")
        # follower_2 3 m ahead of follower 1 (on its way to the slot) and closing at 1 m/s: with
        # rho = alpha ||d|| = 1 m, h = 1 m/s and n u >= 1.5 m/s^2 (N2), n pointing back along -x.
        closing = [entry("leader", SLOT), entry("follower_2", [3.0, 0.0], [-1.0, 0.0])]

        def bound(status):
            return status.binding_neighbour == "follower_2" and status.neighbour_projected

        for _ in range(int(2 * self.deadline / 0.02)):
            self.send(closing)
            rospy.sleep(0.02)
            if self.latest() is not None and bound(self.latest()):
                break
        status = self.latest()
        self.assertTrue(bound(status), f"binding {status.binding_neighbour!r}")
        self.assertLess(status.command[0], -1.0)  # away from it, although the slot is ahead
        self.assertAlmostEqual(status.nearest_neighbour, 3.0, delta=0.2)
        self.assertGreater(status.neighbour_constraints, 0)

    def test_3_floods_leave_the_node_running(self):
        self.send(calm_crowd())
        self.wait(lambda s: s.neighbours_fresh, "no fresh array")
        before = self.rejected()
        flood = [entry(f"agent_{j}", [10.0 + 0.01 * j, 3.0], [0.0, 0.0])
                 for j in range(rospy.get_param("~flood_entries"))]
        for _ in range(rospy.get_param("~flood_messages")):
            self.send(flood)
        self.wait(lambda s: s.neighbours_sent == len(flood) and s.neighbours_sensed == 64,
                  "the largest arrays were not taken (the nearest 64 used)")
        oversized = [entry("agent", [10.0, 3.0])] * rospy.get_param("~oversized_entries")
        self.send(oversized)
        self.wait(lambda s: s.rejected_neighbours == before + 1, "an oversized array was taken")
        self.send(calm_crowd())
        self.wait(lambda s: s.neighbours_sent == 4 and s.mode == FollowerStatus.MODE_TRACKING,
                  "the follower did not take a good array after the flood")


if __name__ == "__main__":
    rospy.init_node("test_bad_neighbours")
    rostest.rosrun(PACKAGE, "bad_neighbours", BadNeighbours, sys.argv)
