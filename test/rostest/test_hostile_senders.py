#!/usr/bin/python3
"""rostest: hostile senders on the paper's Run 2 (test/rostest/hostile_senders.test), the plant
driving the simulated clock. Asserts that
 1. a second publisher on the follower's measurements takes nothing: the follower follows the
    plant (its xi equals the plant's within ~xi_tolerance, ||xi|| <= ~max_xi_bound) and its
    diagnostics report the other publisher (ERROR, foreign_messages > 0), and stop reporting it
    10 s after its latest message;
 2. one measurement or leader broadcast stamped ~forged_ahead s ahead by the input's own
    publisher costs at most its timeout plus ~recovery_margin, under ~clock_skew/policy receipt
    and estimate; one stamped ~implausible_ahead s ahead as well;
 3. one tf transform of the target stamped ~tf_ahead s ahead leaves a follower on tf tracking;
 4. the command adapter follows its first command publisher and reports a second one.

Parameters: ~seed (the forged messages' times; a failure names it), ~wall_deadline (s) for each
awaited condition, and those of each case (hostile_senders.test)."""

import copy
import math
import random
import sys
import threading
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import AccelStamped, TransformStamped, Vector3Stamped
from projection_collision_avoidance.msg import (FollowerStatus, LeaderBroadcast,
                                                RelativeMeasurement)
from tf2_msgs.msg import TFMessage

import ros_test_helpers as helpers

PACKAGE = "projection_collision_avoidance"
SEPARATION = 5.0  # m, d of Run 2 (config/scenarios/paper_run2.yaml)
RELAYS = ("relay_receipt", "relay_estimate")
FOLLOWERS = ("follower", "tf_follower") + RELAYS


def seconds(stamp):
    return stamp.to_sec()


class Senders:
    """What the nodes publish and the test's own senders: the intruder on the follower's
    measurements, the relays (with their forgeries) and the second command publisher."""

    def __init__(self):
        self.lock = threading.Lock()
        self.me = rospy.get_name()
        self.statuses = {name: [] for name in FOLLOWERS}  # (tick s, status)
        self.diagnostics = {}  # node name -> the latest DiagnosticStatus
        self.plant_xi = []  # (stamp s, (position error, velocity)) of the plant's measurements
        self.intruder_offset = None  # m; None: the intruder is silent
        self.intruder_lead = 0.0
        self.intruder_sent = 0
        self.forge_measurement = []  # seconds ahead, one forged measurement each
        self.forge_broadcast = []
        self.forged = {}  # "measurement"/"broadcast" -> stamp (s) of the message forged
        self.commands = {}  # stamp (ns) -> x of the first command publisher
        self.foreign_command = None  # m/s^2; None: the second command publisher is silent
        self.foreign_sent = 0
        self.outputs = []  # (stamp ns, x) of the adapter's setpoint_accel
        pub = lambda topic, kind: rospy.Publisher(topic, kind, queue_size=100)  # noqa: E731
        self.intruder = pub("/follower/relative_measurement", RelativeMeasurement)
        self.relayed = {name: pub(f"/{name}/relayed_measurement", RelativeMeasurement)
                        for name in RELAYS}
        self.relayed_broadcasts = {name: pub(f"/{name}/relayed_broadcast", LeaderBroadcast)
                                   for name in RELAYS}
        self.second_commander = pub("/relay_estimate/command", AccelStamped)
        self.tf = pub("/tf", TFMessage)
        for name in FOLLOWERS:
            rospy.Subscriber(f"/{name}/status", FollowerStatus, self.on_status, name,
                             queue_size=1000)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=100)
        rospy.Subscriber("/follower/relative_measurement", RelativeMeasurement,
                         self.on_measurement, queue_size=1000)
        rospy.Subscriber("/leader/broadcast", LeaderBroadcast, self.on_broadcast,
                         queue_size=1000)
        rospy.Subscriber("/relay_estimate/command", AccelStamped, self.on_command,
                         queue_size=1000)
        rospy.Subscriber("/adapter/setpoint_accel", Vector3Stamped, self.on_output,
                         queue_size=1000)

    def mine(self, msg):
        return msg._connection_header.get("callerid") == self.me

    def on_status(self, msg, name):
        with self.lock:
            self.statuses[name].append((seconds(msg.header.stamp), msg))

    def on_diagnostics(self, msg):
        with self.lock:
            for status in msg.status:
                self.diagnostics[status.name.split(":")[0].strip().lstrip("/")] = status

    def on_measurement(self, msg):
        if self.mine(msg):
            return
        with self.lock:
            self.plant_xi.append((seconds(msg.header.stamp),
                                  (msg.position[0] - SEPARATION, msg.velocity[0])))
            offset, lead = self.intruder_offset, self.intruder_lead
            forge = self.forge_measurement.pop(0) if self.forge_measurement else None
        for publisher in self.relayed.values():
            publisher.publish(msg)
        if forge is not None:
            forged = copy.deepcopy(msg)
            forged.header.stamp = msg.header.stamp + rospy.Duration(forge)
            for publisher in self.relayed.values():
                publisher.publish(forged)
            with self.lock:
                self.forged["measurement"] = seconds(msg.header.stamp)
        if offset is not None:
            intruding = copy.deepcopy(msg)
            intruding.header.stamp = msg.header.stamp + rospy.Duration(lead)
            intruding.position = [msg.position[0] + offset]
            self.intruder.publish(intruding)
            with self.lock:
                self.intruder_sent += 1

    def on_broadcast(self, msg):
        with self.lock:
            forge = self.forge_broadcast.pop(0) if self.forge_broadcast else None
        for publisher in self.relayed_broadcasts.values():
            publisher.publish(msg)
        if forge is not None:
            forged = copy.deepcopy(msg)
            forged.header.stamp = msg.header.stamp + rospy.Duration(forge)
            for publisher in self.relayed_broadcasts.values():
                publisher.publish(forged)
            with self.lock:
                self.forged["broadcast"] = seconds(msg.header.stamp)

    def on_command(self, msg):
        if self.mine(msg):
            return
        with self.lock:
            self.commands[msg.header.stamp.to_nsec()] = msg.accel.linear.x
            foreign = self.foreign_command
        if foreign is not None:
            other = copy.deepcopy(msg)
            other.header.stamp = msg.header.stamp + rospy.Duration(0.0025)
            other.accel.linear.x = foreign
            self.second_commander.publish(other)
            with self.lock:
                self.foreign_sent += 1

    def on_output(self, msg):
        with self.lock:
            self.outputs.append((msg.header.stamp.to_nsec(), msg.vector.x))

    def latest(self, name):
        with self.lock:
            return self.statuses[name][-1] if self.statuses[name] else (None, None)

    def since(self, name, start, end=math.inf):
        with self.lock:
            return [s for t, s in self.statuses[name] if start <= t <= end]


def values(status):
    return {v.key: v.value for v in status.values}


class HostileSenders(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.seed = rospy.get_param("~seed")
        cls.rng = random.Random(cls.seed)
        cls.deadline = rospy.get_param("~wall_deadline")
        cls.bound = rospy.get_param("~max_xi_bound")
        cls.senders = Senders()

    def wait_for(self, condition, what):
        helpers.wait_for(self, condition, f"{what} (seed {self.seed})", self.deadline)

    def now(self):
        return rospy.Time.now().to_sec()

    def wait_until(self, t, what):
        self.wait_for(lambda: self.now() >= t, f"simulated time does not reach {t} s: {what}")

    def tracking(self, name):
        _, status = self.senders.latest(name)
        return status is not None and status.mode == FollowerStatus.MODE_TRACKING

    def track_everywhere(self):
        for name in FOLLOWERS:
            self.wait_for(lambda n=name: self.tracking(n), f"{name} does not track")

    def diagnostics(self, node):
        with self.senders.lock:
            return self.senders.diagnostics.get(node)

    def test_1_second_publisher_takes_nothing(self):
        self.track_everywhere()
        lead = rospy.get_param("~intruder_lead")
        tolerance = rospy.get_param("~xi_tolerance")
        with self.senders.lock:
            self.senders.intruder_lead = lead
            self.senders.intruder_offset = rospy.get_param("~intruder_offset")
        start = self.now()
        self.wait_until(rospy.get_param("~intrusion_until"), "intrusion")

        def reported():
            status = self.diagnostics("follower/controller")
            return (status is not None and status.level == DiagnosticStatus.ERROR and
                    "another publisher" in status.message and
                    int(values(status).get("foreign_messages", "0")) > 0)
        self.wait_for(reported, "the follower's diagnostics do not report another publisher")
        with self.senders.lock:
            self.senders.intruder_offset = None
            sent = self.senders.intruder_sent
            plant = list(self.senders.plant_xi)
        HostileSenders.intrusion_end = self.now()
        end = self.now()
        statuses = self.senders.since("follower", start, end)
        self.assertGreater(sent, 0, "the intruder sent nothing")
        self.assertGreater(len(statuses), 50, "too few statuses during the intrusion")
        largest = max(s.xi_norm for s in statuses)
        self.assertLessEqual(largest, self.bound, f"max ||xi|| {largest}")
        # Each status' xi is the plant's measurement of a recent tick, never the intruder's.
        worst = 0.0
        held = rospy.get_param("~measurement_timeout")  # the oldest measurement still fresh
        for status in statuses:
            t = seconds(status.header.stamp)
            gap = min((abs(status.xi[0] - p) + abs(status.xi[1] - v)
                       for stamp, (p, v) in plant if t - held <= stamp <= t + lead),
                      default=math.inf)
            worst = max(worst, gap)
        self.assertLessEqual(worst, tolerance, "the follower used another publisher's measurement")
        foreign = values(self.diagnostics("follower/controller"))
        rospy.loginfo("hostile_senders: intruder sent %d measurements; max ||xi|| %.4f m; "
                      "status xi within %.2e of the plant's; diagnostics foreign_messages %s, "
                      "input_handovers %s", sent, largest, worst, foreign["foreign_messages"],
                      foreign["input_handovers"])

    def recovery(self, name, forged_at, timeout, fresh_field, count_field, what):
        """Simulated s from the forged message to the end of the last tick of `name` that was not
        tracking on fresh input (mode tracking and `fresh_field`: the input younger than its
        timeout) or at which the input's own sender was refused (`count_field`, the refusal
        count, grew beyond the forged message itself), over the timeout plus ~recovery_margin and
        ~observe_after after it; 0 when there is none. A lock-out refuses the sender's messages;
        a late one (the test's relay under load) is neither refused nor, within the timeout,
        stale. Asserts ticks after it."""
        window = timeout + rospy.get_param("~recovery_margin") + rospy.get_param("~observe_after")
        self.wait_for(lambda: (self.senders.latest(name)[0] or 0.0) >= forged_at + window,
                      f"{name}: no ticks {window} s after {what}")
        earlier = self.senders.since(name, 0.0, forged_at)
        self.assertTrue(earlier, f"{name}: no tick before {what}")
        counted = getattr(earlier[-1], count_field)
        statuses = self.senders.since(name, forged_at, forged_at + window)
        bad = []
        for status in statuses:
            count = getattr(status, count_field)
            refused = count > counted and count - getattr(earlier[-1], count_field) > 1
            counted = count
            if refused or not (status.mode == FollowerStatus.MODE_TRACKING and
                               getattr(status, fresh_field)):
                bad.append(status)
        if bad:
            rospy.loginfo("hostile_senders: %s after %s: refusing or not tracking on fresh input "
                          "at %s", name, what,
                          [(round(seconds(s.header.stamp) - forged_at, 3), s.mode,
                            getattr(s, count_field)) for s in bad][:40])
        last = max((seconds(s.header.stamp) for s in bad), default=forged_at)
        after = [s for s in statuses if seconds(s.header.stamp) > last]
        self.assertGreater(len(after), 10, f"{name}: too few ticks after {what}")
        period = seconds(after[1].header.stamp) - seconds(after[0].header.stamp)
        return last - forged_at + (period if bad else 0.0)

    def forge(self, kind, ahead, timeout):
        """Forges one `kind` ("measurement" or "broadcast") stamped `ahead` s ahead in both
        relays; returns each relay follower's recovery time (s)."""
        self.track_everywhere()
        # A seeded wait, so that the forgery falls at a different phase of the run.
        self.wait_until(self.now() + self.rng.uniform(0.2, 0.7), "before a forgery")
        with self.senders.lock:
            self.senders.forged.pop(kind, None)
            getattr(self.senders, "forge_" + kind).append(ahead)
        self.wait_for(lambda: kind in self.senders.forged, f"no {kind} to forge")
        forged_at = self.senders.forged[kind]
        margin = rospy.get_param("~recovery_margin")
        times = {}
        for name in RELAYS:
            fields = (("measurement_fresh", "rejected_measurements") if kind == "measurement" else
                      ("leader_fresh", "rejected_leader_broadcasts"))
            times[name] = self.recovery(name, forged_at, timeout, *fields,
                                        f"a {kind} {ahead} s ahead")
            self.assertLessEqual(times[name], timeout + margin,
                                 f"{name}: {kind} {ahead} s ahead (seed {self.seed})")
        restarts = {name: values(self.diagnostics(f"{name}/controller")).get("input_restarts")
                    for name in RELAYS if self.diagnostics(f"{name}/controller") is not None}
        rospy.loginfo("hostile_senders: %s stamped %.0f s ahead: recovered in %s s; "
                      "input_restarts %s", kind, ahead,
                      {n: round(t, 3) for n, t in times.items()}, restarts)
        return times

    def test_2_forged_stamps_of_the_holder(self):
        measurement_timeout = rospy.get_param("~measurement_timeout")
        leader_timeout = rospy.get_param("~leader_timeout")
        for ahead in (rospy.get_param("~forged_ahead"), rospy.get_param("~implausible_ahead")):
            self.forge("measurement", ahead, measurement_timeout)
            self.forge("broadcast", ahead, leader_timeout)

    def test_3_forged_tf_transform(self):
        self.track_everywhere()
        self.wait_for(lambda: self.senders.tf.get_num_connections() > 0, "/tf unheard")
        forged = TransformStamped()
        forged.header.stamp = rospy.Time.now() + rospy.Duration(rospy.get_param("~tf_ahead"))
        forged.header.frame_id, forged.child_frame_id = "world", "leader"
        forged.transform.translation.x = 100.0
        forged.transform.rotation.w = 1.0
        start = self.now()
        self.senders.tf.publish(TFMessage(transforms=[forged]))
        self.wait_until(start + rospy.get_param("~watch_time"), "watching the tf follower")
        statuses = self.senders.since("tf_follower", start)
        self.assertGreater(len(statuses), 50, "too few statuses of the tf follower")
        lost = [seconds(s.header.stamp) for s in statuses if s.mode != FollowerStatus.MODE_TRACKING]
        self.assertFalse(lost, f"the tf follower stopped tracking at {lost[:3]}")
        largest = max(s.xi_norm for s in statuses)
        self.assertLessEqual(largest, self.bound, f"max ||xi|| {largest}")
        rospy.loginfo("hostile_senders: after a transform %.0f s ahead, %d ticks tracking, "
                      "max ||xi|| %.4f m", rospy.get_param("~tf_ahead"), len(statuses), largest)

    def test_4_second_command_publisher(self):
        self.track_everywhere()
        self.wait_for(lambda: self.senders.second_commander.get_num_connections() > 0,
                      "the adapter does not listen")
        foreign = rospy.get_param("~foreign_command")
        tolerance = rospy.get_param("~command_tolerance")
        with self.senders.lock:
            first = len(self.senders.outputs)
            self.senders.foreign_command = foreign
        self.wait_until(self.now() + rospy.get_param("~command_time"), "second commands")

        def reported():
            status = self.diagnostics("adapter")
            return (status is not None and status.level == DiagnosticStatus.ERROR and
                    "another publisher on command" in status.message and
                    int(values(status).get("foreign_commands", "0")) > 0)
        self.wait_for(reported, "the adapter's diagnostics do not report another publisher")
        with self.senders.lock:
            self.senders.foreign_command = None
            outputs = self.senders.outputs[first:]
            commands = dict(self.senders.commands)
            sent = self.senders.foreign_sent
        self.assertGreater(sent, 0, "the second publisher sent nothing")
        self.assertGreater(len(outputs), 50, "too few outputs of the adapter")
        for stamp, x in outputs:
            self.assertIn(stamp, commands, f"an output stamped {stamp} ns is no first command")
            self.assertAlmostEqual(x, commands[stamp], delta=tolerance)
        counts = values(self.diagnostics("adapter"))
        rospy.loginfo("hostile_senders: %d commands of a second publisher; %d outputs, all the "
                      "first publisher's; foreign_commands %s", sent, len(outputs),
                      counts["foreign_commands"])

    def test_5_report_ends_after_the_intruder(self):
        end = getattr(HostileSenders, "intrusion_end", None)
        if end is None:
            self.skipTest("no intrusion")
        self.wait_until(end + 10.5, "ten seconds after the intruder")

        def quiet():
            status = self.diagnostics("follower/controller")
            return (status is not None and self.now() > end + 10.5 and
                    "another publisher" not in status.message)
        self.wait_for(quiet, "the diagnostics still report the other publisher")


if __name__ == "__main__":
    rospy.init_node("test_hostile_senders")
    rostest.rosrun(PACKAGE, "hostile_senders", HostileSenders, sys.argv)
