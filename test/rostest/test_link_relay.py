#!/usr/bin/python3
"""rostest: link_relay's queue (test/rostest/link_relay.test).

- A broadcast stamped far ahead (beyond ~max_future_stamp) is refused, and the ones after it are
  released at their own time: stamp + ~latency, up to ~lateness late.
- A broadcast stamped within ~max_future_stamp ahead is released after one sent later but
  stamped now (release by due time, not by arrival).
- With ~max_in_flight_bytes, broadcasts sent faster than the link releases them are dropped
  oldest first: the newest that fit in the bound come out, no more.
Parameters: ~latency, ~small_latency, ~max_in_flight_bytes, ~max_future_stamp, ~lateness (s),
~wall_deadline (s).
"""

import io
import sys
import threading
import time
import unittest

import rospy
import rostest
from projection_collision_avoidance.msg import LeaderBroadcast

import ros_test_helpers as helpers


class LinkRelayTest(unittest.TestCase):
    def connect(self, link):
        """Publisher and subscriber of relay @p link; records (arrival wall s, message)."""
        self.lock = threading.Lock()
        self.received = []
        self.pub = rospy.Publisher(f"/{link}/input", LeaderBroadcast, queue_size=100)
        self.sub = rospy.Subscriber(f"/{link}/output", LeaderBroadcast, self.keep)
        helpers.wait_for(self, lambda: self.pub.get_num_connections() > 0 and
                         self.sub.get_num_connections() > 0,
                         f"{link} and the test never connected", rospy.get_param("~wall_deadline"))

    def keep(self, msg):
        with self.lock:
            self.received.append((rospy.Time.now().to_sec(), msg))

    def send(self, stamp, marker, disturbance=0):
        msg = LeaderBroadcast()
        msg.header.stamp = stamp
        msg.header.frame_id = "world"
        msg.position = [marker]
        msg.velocity = [0.0]
        msg.input = [0.0]
        msg.disturbance = [0.5] * disturbance
        self.pub.publish(msg)
        return msg

    def markers(self):
        with self.lock:
            return [m.position[0] for _, m in self.received]

    def test_a_broadcast_stamped_ahead_holds_back_no_later_one(self):
        self.connect("link")
        latency = rospy.get_param("~latency")
        lateness = rospy.get_param("~lateness")
        ahead = rospy.get_param("~max_future_stamp")
        # Far ahead: refused. Within ~max_future_stamp: held until its own release.
        self.send(rospy.Time.now() + rospy.Duration(1000.0), -1.0)
        self.send(rospy.Time.now() + rospy.Duration(0.8 * ahead), -2.0)
        stamps = {}
        for k in range(10):
            stamps[float(k)] = self.send(rospy.Time.now(), float(k)).header.stamp.to_sec()
            time.sleep(0.02)
        helpers.wait_for(self, lambda: len(self.markers()) >= 11,
                         f"{self.markers()} came out", rospy.get_param("~wall_deadline"))
        with self.lock:
            received = list(self.received)
        markers = [m.position[0] for _, m in received]
        self.assertNotIn(-1.0, markers, "the broadcast stamped 1000 s ahead was relayed")
        self.assertIn(-2.0, markers)
        # The one stamped ahead comes after those stamped now that are due before it.
        self.assertGreater(markers.index(-2.0), markers.index(0.0), markers)
        for arrival, msg in received:
            marker = msg.position[0]
            if marker >= 0.0:
                delay = arrival - stamps[marker]
                self.assertGreaterEqual(delay, latency - 0.02, f"broadcast {marker} early")
                self.assertLessEqual(delay, latency + lateness, f"broadcast {marker} late")

    def test_the_bytes_held_stay_within_the_bound(self):
        self.connect("link_small")
        bound = rospy.get_param("~max_in_flight_bytes")
        sample = self.make_sized(100)
        fit = bound // sample
        self.assertGreater(fit, 1)
        count = 3 * fit
        start = rospy.Time.now()
        for k in range(count):  # all within far less than the link's latency
            self.send(start + rospy.Duration(0.001 * k), float(k), disturbance=100)
        helpers.wait_for(self, lambda: len(self.markers()) >= fit,
                         f"{self.markers()} came out", rospy.get_param("~wall_deadline"))
        # Half a second past the last release: whatever else was held would have come out.
        helpers.wait_for(self, lambda: rospy.Time.now() > start + rospy.Duration(
            rospy.get_param("~small_latency") + 0.5), "time stood still",
            rospy.get_param("~wall_deadline"))
        self.assertEqual(self.markers(), [float(k) for k in range(count - fit, count)])

    @staticmethod
    def make_sized(disturbance):
        """Serialised bytes of a broadcast with @p disturbance entries (roscpp's size too)."""
        msg = LeaderBroadcast()
        msg.header.frame_id = "world"
        msg.position = [0.0]
        msg.velocity = [0.0]
        msg.input = [0.0]
        msg.disturbance = [0.5] * disturbance
        buffer = io.BytesIO()
        msg.serialize(buffer)
        return len(buffer.getvalue())


if __name__ == "__main__":
    rospy.init_node("test_link_relay")
    rostest.rosrun("projection_collision_avoidance", "test_link_relay", LinkRelayTest, sys.argv)
