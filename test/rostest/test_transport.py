#!/usr/bin/python3
"""rostest: the follower's ~transport (test/rostest/transport.test, on launch/pair.launch).

Asks the follower node for its connections (the ROS slave API's getBusInfo) and checks that its
subscriptions of ~topics use ~expected (TCPROS or UDPROS), and that it tracks over them.
Parameters: ~node, ~topics, ~expected, ~wall_deadline.
"""

import sys
import threading
import unittest
import xmlrpc.client

import rosgraph
import rospy
import rostest
from projection_collision_avoidance.msg import FollowerStatus

import ros_test_helpers as helpers


class Transport(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.tracking = 0
        rospy.Subscriber("/follower/status", FollowerStatus, self.keep)

    def keep(self, msg):
        with self.lock:
            self.tracking += msg.mode == FollowerStatus.MODE_TRACKING

    def transports(self):
        master = rosgraph.Master("/test_transport")
        uri = master.lookupNode(rospy.get_param("~node"))
        code, _, info = xmlrpc.client.ServerProxy(uri).getBusInfo("/test_transport")
        self.assertEqual(code, 1)
        # Each entry: connection id, the other end, direction ("i" in, "o" out), transport,
        # topic, connected.
        return {(entry[4], entry[3]) for entry in info if entry[2] == "i"}

    def test_the_subscriptions_use_the_transport(self):
        deadline = rospy.get_param("~wall_deadline")
        expected = rospy.get_param("~expected")
        topics = rospy.get_param("~topics")
        helpers.wait_for(self, lambda: all(any(t == topic for t, _ in self.transports())
                                           for topic in topics),
                         f"the follower is not connected to {topics}", deadline)
        seen = self.transports()
        for topic in topics:
            kinds = {kind for t, kind in seen if t == topic}
            self.assertEqual(kinds, {expected}, f"{topic}: {kinds}")
        helpers.wait_for(self, lambda: self.tracking >= 100,
                         "the follower does not track over it", deadline)


if __name__ == "__main__":
    rospy.init_node("test_transport")
    rostest.rosrun("projection_collision_avoidance", "test_transport", Transport, sys.argv)
