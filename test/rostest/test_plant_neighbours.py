#!/usr/bin/python3
"""rostest: the plant's `<follower>/neighbours` and `world` (test/rostest/plant_neighbours.test).

The plant alone on a formation scenario with formation.neighbours. Each follower's neighbours
must name the other agents, never itself; each entry must be the difference of the two agents'
odometry of the same stamp; an agent farther than the radius must be absent and a nearer one
present; the stamp and frame must be those of the tick's relative_measurement, and the target's
entry must equal it minus the world's noise of that tick (drawn here as doc/formations.md says).
The world acts: the pushed follower's velocity leaves the leader's by the push while the others'
stay equal to it, and the commanded follower's applied command is its command cut to its
vehicle's limit. A plant without formation.neighbours advertises no `neighbours`; its gusts,
which start after its scenario's simulation.duration, act until its ~duration.
Parameters: ~radius (m), ~period (s), ~world_frame, ~targets ({follower: target}), ~pushed,
~push_start, ~push_end (s), ~push_velocity (m/s), ~commanded, ~command, ~applied_command
(m/s^2), ~seed, ~noise_position (m), ~noise_velocity (m/s), ~plain_namespace, ~gust_start (s),
~gust_min_deviation (m/s), ~end_time (s), ~min_matched_fraction, ~exact_tolerance,
~push_tolerance, ~radius_margin, ~wall_deadline (s).
"""

import math
import sys
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import AccelStamped
from nav_msgs.msg import Odometry
from projection_collision_avoidance.msg import NeighbourArray, RelativeMeasurement

import ros_test_helpers as helpers

AXES = ("x", "y", "z")
MASK = (1 << 64) - 1


def splitmix64(x):
    z = (x + 0x9E3779B97F4A7C15) & MASK
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return z ^ (z >> 31)


def world_uniform(seed, stream, count):
    return (splitmix64(splitmix64(seed) ^ ((stream << 40) | count)) >> 11) * 2.0 ** -53


def world_noise(index, tick, entry, k):
    """The world's noise on entry `entry` of follower `index`'s relative state at tick `tick`."""
    sigma = rospy.get_param("~noise_position" if entry < k else "~noise_velocity")
    seed = rospy.get_param("~seed")
    count = tick * 2 * k + entry
    a = world_uniform(seed, 4 * index + 1, 2 * count)
    b = world_uniform(seed, 4 * index + 1, 2 * count + 1)
    return sigma * math.sqrt(-2.0 * math.log1p(-a)) * math.cos(6.283185307179586 * b)


def vector(msg, k):
    return [getattr(msg, axis) for axis in AXES[:k]]


def difference(a, b):
    return [x - y for x, y in zip(a, b)]


class PlantNeighbours(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        p = rospy.get_param
        cls.targets = p("~targets")
        cls.followers = sorted(cls.targets)
        cls.agents = ["leader"] + cls.followers
        cls.k = len(p("~command"))
        cls.lock = threading.Lock()
        cls.odom = {a: {} for a in cls.agents}         # stamp (ns) -> (p, v)
        cls.measured = {f: {} for f in cls.followers}  # stamp (ns) -> RelativeMeasurement
        cls.sensed = {f: {} for f in cls.followers}    # stamp (ns) -> NeighbourArray
        cls.applied = []
        plain = p("~plain_namespace")
        cls.plain = {a: {} for a in cls.agents}  # the plain plant's stamp (ns) -> velocity
        cls.commander = rospy.Publisher(f"/{p('~commanded')}/command", AccelStamped,
                                        queue_size=10)
        cls.subscribers = [rospy.Subscriber(f"/{p('~commanded')}/applied_command", AccelStamped,
                                            lambda m: cls.keep(cls.applied, None, m))]
        for agent in cls.agents:
            cls.subscribers.append(rospy.Subscriber(f"/{agent}/odom", Odometry, cls.on_odom,
                                                    callback_args=agent))
            cls.subscribers.append(rospy.Subscriber(
                f"{plain}/{agent}/odom", Odometry,
                lambda m, a=agent: cls.keep(cls.plain[a], m.header.stamp,
                                            vector(m.twist.twist.linear, cls.k))))
        for follower in cls.followers:
            cls.subscribers.append(rospy.Subscriber(
                f"/{follower}/relative_measurement", RelativeMeasurement,
                lambda m, f=follower: cls.keep(cls.measured[f], m.header.stamp, m)))
            cls.subscribers.append(rospy.Subscriber(
                f"/{follower}/neighbours", NeighbourArray,
                lambda m, f=follower: cls.keep(cls.sensed[f], m.header.stamp, m)))
        # Every topic past ~end_time (the plant ticks once the test listens).
        end_ns = int(p("~end_time") * 1e9)
        end = time.monotonic() + p("~wall_deadline")
        while time.monotonic() < end and not rospy.is_shutdown() and not cls.reached(end_ns):
            time.sleep(0.01)

    @classmethod
    def keep(cls, store, stamp, msg):
        with cls.lock:
            if stamp is None:
                store.append(msg)
            else:
                store[stamp.to_nsec()] = msg

    @classmethod
    def on_odom(cls, msg, agent):
        state = (vector(msg.pose.pose.position, cls.k), vector(msg.twist.twist.linear, cls.k))
        cls.keep(cls.odom[agent], msg.header.stamp, state)
        if agent == rospy.get_param("~commanded"):
            command = AccelStamped()
            command.header.stamp = msg.header.stamp
            command.header.frame_id = rospy.get_param("~world_frame")
            for axis, value in zip(AXES, rospy.get_param("~command")):
                setattr(command.accel.linear, axis, value)
            cls.commander.publish(command)

    @classmethod
    def reached(cls, end_ns):
        with cls.lock:
            stores = list(cls.odom.values()) + list(cls.measured.values()) + \
                list(cls.sensed.values()) + list(cls.plain.values())
            return all(store and max(store) >= end_ns for store in stores)

    def snapshot(self):
        end_ns = int(rospy.get_param("~end_time") * 1e9)
        self.assertTrue(self.reached(end_ns), "a topic did not reach ~end_time in time")
        with self.lock:
            return ({a: dict(s) for a, s in self.odom.items()},
                    {f: dict(s) for f, s in self.measured.items()},
                    {f: dict(s) for f, s in self.sensed.items()}, list(self.applied),
                    {a: dict(s) for a, s in self.plain.items()})

    def assertClose(self, actual, expected, tolerance, what):
        self.assertEqual(len(actual), len(expected), what)
        for a, e in zip(actual, expected):
            self.assertLessEqual(abs(a - e), tolerance, f"{what}: {list(actual)} != {expected}")

    def expected_ticks(self):
        return int(rospy.get_param("~end_time") / rospy.get_param("~period")) + 1

    def test_topics_advertised_only_with_neighbours(self):
        def published():
            return dict(rospy.get_published_topics())
        for follower in self.followers:
            self.assertEqual(published().get(f"/{follower}/neighbours"),
                             "projection_collision_avoidance/NeighbourArray", follower)
        plain = rospy.get_param("~plain_namespace")
        last = self.followers[-1]
        # The plain plant advertises agent_markers after every follower's topics.
        helpers.wait_for(
            self, lambda: f"{plain}/agent_markers" in published() and
            f"{plain}/{last}/relative_measurement" in published(),
            "the plant without formation.neighbours did not start",
            rospy.get_param("~wall_deadline"))
        extra = [t for t in published() if t.startswith(plain + "/") and t.endswith("neighbours")]
        self.assertEqual(extra, [], "neighbours advertised without formation.neighbours")

    def test_entries_are_the_other_agents_within_the_radius(self):
        odom, _, sensed, _, _ = self.snapshot()
        radius = rospy.get_param("~radius")
        margin = rospy.get_param("~radius_margin")
        tolerance = rospy.get_param("~exact_tolerance")
        seen = {}  # (follower, agent) -> the set of presences seen
        for follower in self.followers:
            matched = 0
            for stamp, msg in sensed[follower].items():
                ids = [n.id for n in msg.neighbours]
                self.assertEqual(len(ids), len(set(ids)), f"{follower}: repeated ids {ids}")
                self.assertNotIn(follower, ids, f"{follower} senses itself")
                self.assertTrue(set(ids) <= set(self.agents), f"{follower}: ids {ids}")
                if not all(stamp in odom[a] for a in self.agents):
                    continue
                matched += 1
                own_p, own_v = odom[follower][stamp]
                entries = {n.id: n for n in msg.neighbours}
                for agent in self.agents:
                    if agent == follower:
                        continue
                    p, v = odom[agent][stamp]
                    distance = math.sqrt(sum(x * x for x in difference(p, own_p)))
                    what = f"{follower} at {stamp * 1e-9:.2f} s, {agent} at {distance:.3f} m"
                    if agent in entries:
                        self.assertLessEqual(distance, radius + margin, what + ": sensed")
                        self.assertClose(entries[agent].position, difference(p, own_p),
                                         tolerance, what + ": position")
                        self.assertClose(entries[agent].velocity, difference(v, own_v),
                                         tolerance, what + ": velocity")
                    else:
                        self.assertGreaterEqual(distance, radius - margin, what + ": not sensed")
                    seen.setdefault((follower, agent), set()).add(agent in entries)
            self.assertGreaterEqual(matched, rospy.get_param("~min_matched_fraction") *
                                    self.expected_ticks(), f"{follower}: too few ticks matched")
        self.assertTrue(any(s == {True} for s in seen.values()), "no agent always sensed")
        self.assertTrue(any(s == {False} for s in seen.values()), "no agent never sensed")
        self.assertTrue(any(s == {True, False} for s in seen.values()),
                        "no agent came into or left the radius")

    def test_stamp_and_frame_are_the_measurements(self):
        _, measured, sensed, _, _ = self.snapshot()
        period_ns = rospy.get_param("~period") * 1e9
        frame = rospy.get_param("~world_frame")
        for follower in self.followers:
            matched = 0
            for stamp, msg in sensed[follower].items():
                ticks = stamp / period_ns
                self.assertLess(abs(ticks - round(ticks)) * period_ns, 1e3,
                                f"{follower}: stamp {stamp} ns off the plant's ticks")
                self.assertEqual(msg.header.frame_id, frame, follower)
                if stamp in measured[follower]:
                    matched += 1
                    self.assertEqual(msg.header.frame_id,
                                     measured[follower][stamp].header.frame_id, follower)
            self.assertGreaterEqual(
                matched, rospy.get_param("~min_matched_fraction") * self.expected_ticks(),
                f"{follower}: too few neighbours with a relative_measurement of their stamp")
            unmatched = set(measured[follower]) - set(sensed[follower])
            self.assertLessEqual(
                len(unmatched),
                (1 - rospy.get_param("~min_matched_fraction")) * self.expected_ticks(),
                f"{follower}: measurements without neighbours of their stamp")

    def test_target_entry_is_the_measurement_without_its_noise(self):
        _, measured, sensed, _, _ = self.snapshot()
        tolerance = rospy.get_param("~exact_tolerance")
        period_ns = rospy.get_param("~period") * 1e9
        compared = 0
        largest_noise = 0.0
        for follower in self.followers:
            target = self.targets[follower]
            index = int(follower.rsplit("_", 1)[1])
            for stamp, msg in sensed[follower].items():
                entry = [n for n in msg.neighbours if n.id == target]
                if not entry or stamp not in measured[follower]:
                    continue
                compared += 1
                tick = round(stamp / period_ns)
                rm = measured[follower][stamp]
                noise = [world_noise(index, tick, e, self.k) for e in range(2 * self.k)]
                largest_noise = max(largest_noise, max(abs(x) for x in noise))
                what = f"{follower} at {stamp * 1e-9:.2f} s, target {target}"
                self.assertClose(entry[0].position, difference(rm.position, noise[:self.k]),
                                 tolerance, what + ": position")
                self.assertClose(entry[0].velocity, difference(rm.velocity, noise[self.k:]),
                                 tolerance, what + ": velocity")
        self.assertGreater(compared, 0, "no target was ever sensed")
        self.assertGreater(largest_noise, 0.5 * rospy.get_param("~noise_position"), "no noise")

    def test_gusts_act_until_the_plants_duration(self):
        _, _, _, _, plain = self.snapshot()
        start_ns = rospy.get_param("~gust_start") * 1e9
        exact = rospy.get_param("~exact_tolerance")
        for follower in self.followers:
            if follower == rospy.get_param("~pushed"):
                continue
            deviation = 0.0
            for stamp, leader_v in plain["leader"].items():
                if stamp not in plain[follower]:
                    continue
                gap = max(abs(x) for x in difference(plain[follower][stamp], leader_v))
                if stamp <= start_ns:
                    self.assertLessEqual(gap, exact, f"{follower} gusted before the gusts")
                else:
                    deviation = max(deviation, gap)
            self.assertGreater(deviation, rospy.get_param("~gust_min_deviation"),
                               f"{follower}: no gust after simulation.duration")

    def test_world_pushes_one_follower(self):
        odom, _, _, _, _ = self.snapshot()
        pushed = rospy.get_param("~pushed")
        commanded = rospy.get_param("~commanded")
        start = rospy.get_param("~push_start")
        end = rospy.get_param("~push_end")
        push = rospy.get_param("~push_velocity")
        exact = rospy.get_param("~exact_tolerance")
        tolerance = rospy.get_param("~push_tolerance")
        before = after = 0
        for stamp, (_, leader_v) in odom["leader"].items():
            t = stamp * 1e-9
            for follower in self.followers:
                if follower in (pushed, commanded) or stamp not in odom[follower]:
                    continue
                self.assertClose(odom[follower][stamp][1], leader_v, exact,
                                 f"{follower} at {t:.2f} s: its velocity left the leader's")
            if stamp not in odom[pushed]:
                continue
            deviation = difference(odom[pushed][stamp][1], leader_v)
            if t <= start:
                before += 1
                self.assertClose(deviation, [0.0] * self.k, exact, f"{pushed} at {t:.2f} s")
            elif t >= end:
                after += 1
                self.assertClose(deviation, push, tolerance, f"{pushed} at {t:.2f} s")
        self.assertGreater(before, 0, "no odometry before the push")
        self.assertGreater(after, 0, "no odometry after the push")

    def test_true_vehicle_limits_the_command(self):
        _, _, _, applied, _ = self.snapshot()
        expected = rospy.get_param("~applied_command")
        tolerance = rospy.get_param("~exact_tolerance")
        driven = [vector(m.accel.linear, self.k) for m in applied if m.accel.linear.x != 0.0]
        self.assertGreater(len(driven), 0.5 * self.expected_ticks(), "too few applied commands")
        for command in driven:
            self.assertClose(command, expected, tolerance, "applied command")


if __name__ == "__main__":
    rospy.init_node("test_plant_neighbours")
    rostest.rosrun(helpers.PACKAGE, "test_plant_neighbours", PlantNeighbours, sys.argv)
