#!/usr/bin/python3
"""rostest: the package's nodes driving Enki robots (test/rostest/enki_pair.test, enki_v.test).

Within ~wall_deadline s each follower of ~followers (namespaces; default the pair's `follower`)
must publish ~min_statuses statuses in MODE_TRACKING, on the bridge's odometry, tf or relative
sensor whose frames carry a leading slash (at 100 Hz, past the leader's push); over that run: each
robot of ~followed_robots (default robot_1) moves (its ground truth at least ~min_travel m from
its start: the adapter's cmd_vel reaches it), and no two robots of ~robots (default robot_0,
robot_1) come closer than ~min_centre_distance m centre to centre (ground truth; two Thymios
touch at about 0.11 m). With ~behind_leader (a turning leader and turning slots), each followed
robot ends behind the leader's heading: in the leader's body frame (its ground-truth yaw), at
least ~behind_margin m behind it. With ~max_path_distance > 0 (a convoy, path slots), each followed
robot's centre stays within it of the path the leader's centre drove (its ground truth, points
5 mm apart) from ~path_after s after its first ground truth on.
"""

import itertools
import math
import sys
import threading
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry

from projection_collision_avoidance.msg import FollowerStatus


class EnkiPair(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.followers = list(rospy.get_param("~followers", ["follower"]))
        self.robots = list(rospy.get_param("~robots", ["robot_0", "robot_1"]))
        self.moving = list(rospy.get_param("~followed_robots", ["robot_1"]))
        self.tracking = {name: 0 for name in self.followers}
        self.truth = {}
        self.yaw = {}
        self.start = {}
        self.min_distance = {pair: math.inf for pair in itertools.combinations(self.robots, 2)}
        self.travel = {robot: 0.0 for robot in self.robots}
        self.path_after = float(rospy.get_param("~path_after", 20.0))
        self.leader_path = []  # the leader's ground truth, points 5 mm apart
        self.path_distance = {robot: 0.0 for robot in self.moving}
        self.first_truth = None
        for name in self.followers:
            rospy.Subscriber(f"/{name}/status", FollowerStatus, self.on_status, name,
                             queue_size=100)
        for robot in self.robots:
            rospy.Subscriber(f"/{robot}/ground_truth", Odometry, self.on_truth, robot,
                             queue_size=100)

    def on_status(self, status, name):
        with self.lock:
            if status.mode == FollowerStatus.MODE_TRACKING:
                self.tracking[name] += 1

    def on_truth(self, msg, robot):
        p = msg.pose.pose.position
        q = msg.pose.pose.orientation
        with self.lock:
            self.truth[robot] = (p.x, p.y)
            self.yaw[robot] = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
            sx, sy = self.start.setdefault(robot, (p.x, p.y))
            self.travel[robot] = max(self.travel[robot], math.hypot(p.x - sx, p.y - sy))
            self.note_path(robot, p.x, p.y)
            for pair in self.min_distance:
                if robot in pair and all(r in self.truth for r in pair):
                    (x0, y0), (x1, y1) = self.truth[pair[0]], self.truth[pair[1]]
                    self.min_distance[pair] = min(self.min_distance[pair],
                                                  math.hypot(x0 - x1, y0 - y1))

    def note_path(self, robot, x, y):
        """Records the leader's path; a followed robot's distance to it once ~path_after passed."""
        now = time.monotonic()
        if self.first_truth is None:
            self.first_truth = now
        if robot == self.robots[0]:
            if not self.leader_path or math.hypot(x - self.leader_path[-1][0],
                                                  y - self.leader_path[-1][1]) >= 0.005:
                self.leader_path.append((x, y))
        elif (robot in self.path_distance and self.leader_path
              and now - self.first_truth >= self.path_after):
            nearest = min(math.hypot(x - px, y - py) for px, py in self.leader_path)
            self.path_distance[robot] = max(self.path_distance[robot], nearest)

    def wait_for(self, condition, deadline, what):
        end = time.monotonic() + deadline
        while time.monotonic() < end and not rospy.is_shutdown():
            with self.lock:
                if condition():
                    return
            time.sleep(0.05)
        with self.lock:
            self.fail(f"{what} (tracking statuses {self.tracking})")

    def test_follower_tracks_and_keeps_the_robots_apart(self):
        deadline = float(rospy.get_param("~wall_deadline", 60.0))
        min_statuses = int(rospy.get_param("~min_statuses", 2000))
        min_centre = float(rospy.get_param("~min_centre_distance", 0.12))
        min_travel = float(rospy.get_param("~min_travel", 0.1))
        end = time.monotonic() + deadline
        self.wait_for(lambda: min(self.tracking.values()) >= 10, end - time.monotonic(),
                      "a follower never tracks: does it refuse the bridge's measurements?")
        self.wait_for(lambda: min(self.tracking.values()) >= min_statuses, end - time.monotonic(),
                      f"a follower has fewer than {min_statuses} tracking statuses")
        with self.lock:
            tracking, travel, distance = dict(self.tracking), dict(self.travel), dict(self.min_distance)
            truth, yaw = dict(self.truth), dict(self.yaw)
        print("enki: tracking statuses %s, travelled %s m, closest centres %s m" % (
            tracking, {r: round(travel[r], 3) for r in self.moving},
            {"-".join(p): round(d, 3) for p, d in distance.items()}), flush=True)
        for robot in self.moving:
            self.assertGreater(travel[robot], min_travel, f"{robot} did not move: no cmd_vel reached it")
        for pair, d in distance.items():
            self.assertGreater(d, min_centre, "%s and %s came too close" % pair)
        max_path = float(rospy.get_param("~max_path_distance", 0.0))
        if max_path > 0.0:
            with self.lock:
                path_distance = dict(self.path_distance)
            print("enki: largest distance from the leader's path after %.0f s: %s m" % (
                self.path_after, {r: round(d, 4) for r, d in path_distance.items()}), flush=True)
            for robot, d in path_distance.items():
                self.assertLessEqual(d, max_path, f"{robot} left the leader's path")
        if rospy.get_param("~behind_leader", False):
            margin = float(rospy.get_param("~behind_margin", 0.1))
            leader = self.robots[0]
            (lx, ly), heading = truth[leader], yaw[leader]
            for robot in self.moving:
                dx, dy = truth[robot][0] - lx, truth[robot][1] - ly
                ahead = math.cos(heading) * dx + math.sin(heading) * dy  # along the leader's heading
                print("enki: %s at %.3f m along %s's heading (%.2f rad)" % (robot, ahead, leader, heading),
                      flush=True)
                self.assertLess(ahead, -margin, f"{robot} is not behind {leader}'s heading")


if __name__ == "__main__":
    rospy.init_node("test_enki_pair")
    rostest.rosrun("projection_collision_avoidance", "enki_pair", EnkiPair, sys.argv)
