#!/usr/bin/python3
"""rostest: generated hostile messages at every input of every node (follower, plant, leader;
as processes or nodelets of one manager), on a simulated clock this test drives. Asserts, with
the contract of doc/boundary.md as an independent oracle: no node exits; the follower counts
exactly the refusals the contract calls for on each of its inputs; every command is finite and
within the acceleration limit; diagnostics stay bounded; tracking resumes with good input; after
the clock restarts from an earlier time the follower brakes, never says fresh with a negative
age, and tracks again on the new timeline.

Parameters: ~seed (a failure names it), ~messages (per input), ~nodes (the processes that must
survive), ~acceleration_limit (m/s^2), ~wall_deadline (s) for each awaited condition."""

import math
import random
import sys
import threading
import time
import unittest

import rosnode
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import AccelStamped
from nav_msgs.msg import Odometry
from projection_collision_avoidance.msg import (FollowerStatus, LeaderBroadcast,
                                                RelativeMeasurement)
from rosgraph_msgs.msg import Clock

import hostile_messages as hostile
import ros_test_helpers as helpers

PACKAGE = "projection_collision_avoidance"
START = 1000.0  # s of simulated time at which the test's clock starts
CLOCK_STEP = 0.002  # s, wall and simulated, between two /clock messages


class Recorder:
    """What the nodes publish, from the nodes only (the test publishes on some of the same
    topics)."""

    def __init__(self):
        self.lock = threading.Lock()
        self.statuses = []
        self.commands = []
        self.largest_diagnostics = 0
        self.plant_outputs = 0
        self.nonfinite = []

    def on_status(self, msg):
        with self.lock:
            self.statuses.append(msg)

    def on_command(self, msg):
        if msg._connection_header.get("callerid") == rospy.get_name():
            return  # the test's own commands to the plant on the same topic
        with self.lock:
            a = msg.accel.linear
            self.commands.append((msg.header.stamp.to_sec(), (a.x, a.y, a.z)))

    def on_diagnostics(self, msg):
        size = sum(len(s.message) + sum(len(v.key) + len(v.value) for v in s.values)
                   for s in msg.status)
        with self.lock:
            self.largest_diagnostics = max(self.largest_diagnostics, size)

    def on_plant_output(self, msg):
        if msg._connection_header.get("callerid") == rospy.get_name():
            return
        p, v = msg.pose.pose.position, msg.twist.twist.linear
        with self.lock:
            self.plant_outputs += 1
            if not all(math.isfinite(x) for x in (p.x, p.y, p.z, v.x, v.y, v.z)):
                self.nonfinite.append(("odometry", msg.header.stamp.to_sec()))

    def latest(self):
        with self.lock:
            return self.statuses[-1] if self.statuses else None


class HostileInputs(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.seed = rospy.get_param("~seed")
        cls.rng = random.Random(cls.seed)
        cls.deadline = rospy.get_param("~wall_deadline")
        cls.limit = rospy.get_param("~acceleration_limit")
        cls.record = Recorder()
        rospy.Subscriber("/follower/status", FollowerStatus, cls.record.on_status)
        rospy.Subscriber("/follower/command", AccelStamped, cls.record.on_command)
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.record.on_diagnostics)
        rospy.Subscriber("/leader/odom", Odometry, cls.record.on_plant_output)
        pub = lambda topic, kind: rospy.Publisher(topic, kind, queue_size=10000)  # noqa: E731
        cls.measurements = pub("/follower/relative_measurement", RelativeMeasurement)
        cls.broadcasts = pub("/hostile/leader_broadcast", LeaderBroadcast)
        cls.commands = {name: pub(f"/{name}/command", AccelStamped)
                        for name in ("leader", "follower")}
        cls.odometry = pub("/leader/odom", Odometry)
        cls.clock = pub("/clock", Clock)
        cls.now = START
        cls.last_good = None  # stamp (s) of the test's latest good measurement
        cls.clock_lock = threading.Lock()
        cls.running = True
        cls.clock_thread = threading.Thread(target=cls.run_clock, daemon=True)
        cls.clock_thread.start()

    @classmethod
    def tearDownClass(cls):
        cls.running = False
        cls.clock_thread.join()

    @classmethod
    def run_clock(cls):
        """Simulated time at real speed, one /clock message every CLOCK_STEP s."""
        while cls.running and not rospy.is_shutdown():
            with cls.clock_lock:
                cls.now += CLOCK_STEP
                cls.clock.publish(Clock(clock=hostile.to_time(cls.now)))
            time.sleep(CLOCK_STEP)

    def clock_now(self):
        with self.clock_lock:
            return HostileInputs.now

    def wait_for(self, condition, what):
        helpers.wait_for(self, condition, f"{what} (seed {self.seed})", self.deadline)

    def connected(self, publisher):
        self.wait_for(lambda: publisher.get_num_connections() > 0, f"{publisher.name} unheard")

    def send_measurement(self, stamp, frame, vectors):
        msg = RelativeMeasurement()
        msg.header.stamp, msg.header.frame_id = stamp, frame
        msg.position, msg.velocity = vectors["position"], vectors["velocity"]
        self.measurements.publish(msg)

    def good_measurement(self):
        """A measurement on the slot, stamped after every good one before it."""
        stamp = self.clock_now() - 0.05
        if HostileInputs.last_good is not None and HostileInputs.last_good < self.clock_now():
            stamp = max(stamp, HostileInputs.last_good + 0.001)
        HostileInputs.last_good = stamp
        self.send_measurement(hostile.to_time(stamp), "world",
                              {"position": [5.0], "velocity": [0.0]})

    def track(self):
        """Good measurements until the follower runs its laws on them (tracking, or leader_lost
        once the test's leader broadcasts have stopped)."""
        def tracking():
            self.good_measurement()
            latest = self.record.latest()
            return latest is not None and latest.mode in (FollowerStatus.MODE_TRACKING,
                                                          FollowerStatus.MODE_LEADER_LOST)
        self.wait_for(tracking, "the follower does not track good measurements")

    def assert_alive_and_sane(self):
        for node in rospy.get_param("~nodes"):
            self.assertTrue(rosnode.rosnode_ping(node, max_count=1, verbose=False),
                            f"{node} is gone (seed {self.seed})")
        with self.record.lock:
            commands = list(self.record.commands)
            nonfinite = list(self.record.nonfinite)
        self.assertTrue(commands, "no command")
        for stamp, u in commands:
            self.assertTrue(all(math.isfinite(x) for x in u), f"command {u} at {stamp}")
            self.assertLessEqual(math.sqrt(sum(x * x for x in u)), self.limit + 1e-9,
                                 f"command {u} at {stamp} (seed {self.seed})")
        self.assertFalse(nonfinite, f"non-finite plant output {nonfinite[:3]}")
        self.assertLess(self.record.largest_diagnostics, 20000,
                        "diagnostics grow with what senders send")

    def barrage(self, generator, send, refused, sentinel, seen):
        """Sends a good `sentinel` message (marked), waits until the follower has taken it, then
        the generator's messages, then another sentinel: once that is taken the follower has
        judged everything before it, in order, and its count `refused(status)` must have grown by
        exactly what the contract refuses."""
        def take_sentinel(mark):
            stamp = generator.good_stamp(self.clock_now())
            generator.last_accepted = stamp
            sentinel(stamp, mark)
            self.wait_for(lambda: seen(self.record.latest(), mark), f"sentinel {mark} not taken")
        if HostileInputs.last_good is not None:
            generator.last_accepted = hostile.to_time(HostileInputs.last_good)
        take_sentinel(0.4321)
        before = refused(self.record.latest())
        for _ in range(rospy.get_param("~messages")):
            kind, stamp, frame, vectors, accepted = generator.draw(self.clock_now())
            send(stamp, frame, vectors)
            time.sleep(0.004)
        take_sentinel(0.1234)
        counted = refused(self.record.latest()) - before
        self.assertEqual(counted, generator.refused,
                         f"{counted} refused, the contract refuses {generator.refused} of "
                         f"{generator.refused + generator.accepted} (seed {self.seed})")
        rospy.loginfo("hostile_inputs: %d of %d refused, as the contract says (seed %d)", counted,
                      generator.refused + generator.accepted, self.seed)
        HostileInputs.last_good = hostile.stamp_seconds(generator.last_accepted)

    def test_1_measurements_refused_exactly_as_the_contract_says(self):
        self.connected(self.measurements)
        self.track()
        generator = hostile.Generator(
            self.rng, "world", max_future=0.1, max_age=0.5,
            sizes={"position": (1,), "velocity": (1,)},
            good_values=lambda rng: {"position": [rng.uniform(3, 7)],
                                     "velocity": [rng.uniform(-1, 1)]})
        # Sentinels: positions 5 + mark, which no generated message has (xi = mark).
        self.barrage(generator, self.send_measurement,
                     lambda status: status.rejected_measurements,
                     lambda stamp, mark: self.send_measurement(
                         stamp, "world", {"position": [5.0 + mark], "velocity": [0.0]}),
                     lambda status, mark: abs(status.xi[0] - mark) < 1e-9)
        self.track()
        self.assert_alive_and_sane()

    def send_broadcast(self, stamp, frame, vectors):
        msg = LeaderBroadcast()
        msg.header.stamp, msg.header.frame_id = stamp, frame
        for name, values in vectors.items():
            setattr(msg, name, values)
        self.broadcasts.publish(msg)
        self.good_measurement()  # the broadcast is used while the measurement is fresh

    def test_2_leader_broadcasts_refused_exactly_as_the_contract_says(self):
        self.connected(self.broadcasts)
        self.track()
        generator = hostile.Generator(
            self.rng, "world", max_future=0.1, max_age=0.5,
            sizes={"position": (1,), "velocity": (1,), "input": (1,), "disturbance": (2, 0)},
            good_values=lambda rng: {"position": [rng.uniform(-5, 5)], "velocity": [0.0],
                                     "input": [rng.uniform(-1, 1)], "disturbance": [0.0, 0.0]})
        # Sentinels: a leader input no generated message has, fed forward into the command.
        self.barrage(generator, self.send_broadcast,
                     lambda status: status.rejected_leader_broadcasts,
                     lambda stamp, mark: self.send_broadcast(stamp, "world", {
                         "position": [0.0], "velocity": [0.0], "input": [mark],
                         "disturbance": [0.0, 0.0]}),
                     lambda status, mark: abs(status.feedforward_command[0] - mark) < 1e-9)
        self.assert_alive_and_sane()

    def test_3_plant_and_leader_survive_anything(self):
        for publisher in [self.odometry, *self.commands.values()]:
            self.connected(publisher)
        outputs = self.record.plant_outputs
        for _ in range(rospy.get_param("~messages")):
            now = self.clock_now()
            stamp = self.rng.choice((ros_time(0), hostile.to_time(now),
                                     hostile.to_time(now - 0.01), hostile.to_time(now + 5),
                                     hostile.to_time(self.rng.uniform(0, 4294967295)),
                                     ros_time(*hostile.LATEST)))
            frame = self.rng.choice(("leader", "follower", "world", "", "x" * 100000))
            values = hostile.any_values(self.rng, {"a": 3, "b": 3})
            command = AccelStamped()
            command.header.stamp, command.header.frame_id = stamp, frame
            a = (values["a"] + [0.0, 0.0, 0.0])[:3]
            command.accel.linear.x, command.accel.linear.y, command.accel.linear.z = [
                x if abs(x) < 1e3 or not math.isfinite(x) else 1.0 for x in a]
            self.commands[self.rng.choice(sorted(self.commands))].publish(command)
            odometry = Odometry()
            odometry.header.stamp, odometry.header.frame_id = stamp, frame
            odometry.child_frame_id = self.rng.choice(("leader", "", "y" * 100000))
            p = (values["b"] + [0.0, 0.0, 0.0])[:3]
            odometry.pose.pose.position.x, odometry.pose.pose.position.y = p[0], p[1]
            odometry.twist.twist.linear.x = p[2]
            self.odometry.publish(odometry)
            time.sleep(0.004)
        self.wait_for(lambda: self.record.plant_outputs > outputs + 50, "the plant stopped")
        self.assert_alive_and_sane()

    def test_4_clock_restarted_from_an_earlier_time(self):
        self.connected(self.measurements)
        self.track()
        jumps = self.record.latest().time_jumps
        with self.record.lock:
            seen = len(self.record.statuses)
        with self.clock_lock:
            HostileInputs.now -= 100.0  # a simulator restarted (the clock thread's time)
        self.wait_for(lambda: self.record.latest().time_jumps == jumps + 1,
                      "the jump back is not reported")
        self.wait_for(lambda: self.record.latest().mode == FollowerStatus.MODE_MEASUREMENT_LOST,
                      "no fallback after the jump")
        self.track()  # measurements of the new timeline
        with self.record.lock:
            after = self.record.statuses[seen:]
        for status in after:
            self.assertFalse(status.measurement_fresh and status.measurement_age < 0.0,
                             f"fresh with age {status.measurement_age}")
            if status.measurement_fresh:
                self.assertLessEqual(status.measurement_age, 0.5)
        self.assert_alive_and_sane()


def ros_time(secs, nsecs=0):
    return rospy.Time(secs, nsecs)


if __name__ == "__main__":
    rospy.init_node("test_hostile_inputs")
    rostest.rosrun(PACKAGE, "hostile_inputs", HostileInputs, sys.argv)
