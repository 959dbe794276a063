#!/usr/bin/env python3
"""Independent check of the velocity command's anchor for vehicles slower than the controller
(doc/vehicles.md, "Vehicles slower than the controller"), written from the equations there:

    v_cmd,k = v_anchor,k + a_k h,   v_anchor,k = v(t_m) + sum of dc_j over t_j >= t_m - D,
    dc_j = v_cmd,j - v_anchor,j,

against a vehicle whose state changes every P >= T and then shows the command in force D before,
v(t_m) = c(t_m - D) (the last command sent before t_m - D). Claims checked: the commands realise
the whole commanded acceleration (realised fraction 1) for every P and D; anchoring on v(t_m)
alone realises T / P of it; against a vehicle that cannot exceed its top speed, the command stays
within a (2 (max_delay + T) + h) of it. Plain Python: no numpy, no C++.

Usage: velocity_anchor_reference.py [--xunit FILE]
"""

import argparse
import sys
import unittest

T = 0.01  # s, the control period


def held_vehicle(P, D, a, duration, corrected, top_speed=float("inf"), max_delay=0.3,
                 reverse_at=None):
    """Closed loop of the anchor and a held, delayed 1-D vehicle. Returns (times, velocities,
    commands): the vehicle's velocity and the command at each control tick."""
    hold = int(round(P / T))
    sent = []  # (time, command, increment)
    v = 0.0
    changed_at = 0.0
    times, velocities, commands = [], [], []
    for k in range(int(round(duration / T)) + 1):
        t = k * T
        if k % hold == 0:  # the state changes: the command in force D before, within the limit
            shown = [c for (tj, c, _) in sent if tj < t - D - 1e-12]
            v = min(shown[-1] if shown else 0.0, top_speed)
            changed_at = t
        anchor = v
        if corrected:
            start = max(changed_at - D, t - 2.0 * (max_delay + T))
            anchor += sum(dc for (tj, _, dc) in sent if tj >= start - 1e-12)
        accel = a if reverse_at is None or t < reverse_at else -a
        command = anchor + accel * T
        sent.append((t, command, command - anchor))
        times.append(t)
        velocities.append(v)
        commands.append(command)
    return times, velocities, commands


def realised_fraction(P, D, corrected, a=0.5):
    """Velocity gained per second over the last 2 s of a 4 s steady push, divided by a."""
    times, velocities, _ = held_vehicle(P, D, a, 4.0, corrected)
    start = times.index(2.0) if 2.0 in times else min(range(len(times)),
                                                      key=lambda i: abs(times[i] - 2.0))
    return (velocities[-1] - velocities[start]) / (times[-1] - times[start]) / a


class VelocityAnchorReference(unittest.TestCase):
    def test_the_corrected_anchor_realises_the_whole_acceleration(self):
        for P in (0.01, 0.05, 0.1):
            for steps in (0, 1, 2):  # the delay in state changes
                with self.subTest(P=P, D=steps * P):
                    self.assertAlmostEqual(realised_fraction(P, steps * P, True), 1.0, delta=0.05)

    def test_the_measured_anchor_alone_realises_T_over_P(self):
        for P in (0.05, 0.1):
            with self.subTest(P=P):
                self.assertAlmostEqual(realised_fraction(P, 0.0, False), T / P, delta=0.02)
                self.assertLess(realised_fraction(P, P, False), 1.5 * T / P)

    def test_no_wind_up_against_a_vehicle_at_its_top_speed(self):
        a, top, max_delay = 2.0, 1.0, 0.3
        times, velocities, commands = held_vehicle(0.1, 0.1, a, 10.0, True, top_speed=top,
                                                   max_delay=max_delay, reverse_at=5.0)
        self.assertLessEqual(max(commands), top + a * (2.0 * (max_delay + T) + T) + 1e-9)
        reversed_at = times.index(5.0) if 5.0 in times else int(round(5.0 / T))
        below = next(i for i in range(reversed_at, len(times)) if commands[i] < top)
        self.assertLessEqual(times[below] - times[reversed_at], 2.0 * (max_delay + T) + T)
        self.assertEqual(max(velocities), top)


def write_xunit(path, result, total):
    """The run as a JUnit XML file (read by catkin_test_results)."""
    import os
    import xml.etree.ElementTree as ET
    failed = {test.id(): text for test, text in result.failures + result.errors}
    suite = ET.Element("testsuite", name="velocity_anchor_reference", tests=str(total),
                       failures=str(len(failed)), errors="0")
    for test in VELOCITY_TESTS:
        case = ET.SubElement(suite, "testcase", classname="velocity_anchor_reference",
                             name=test)
        key = next((k for k in failed if k.endswith(test)), None)
        if key is not None:
            ET.SubElement(case, "failure", message=test).text = failed[key]
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    ET.ElementTree(suite).write(path, encoding="utf-8", xml_declaration=True)


VELOCITY_TESTS = unittest.defaultTestLoader.getTestCaseNames(VelocityAnchorReference)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--xunit", help="write a JUnit XML report here")
    args = parser.parse_args()
    suite = unittest.defaultTestLoader.loadTestsFromTestCase(VelocityAnchorReference)
    result = unittest.TextTestRunner(verbosity=2).run(suite)
    if args.xunit:
        write_xunit(args.xunit, result, suite.countTestCases())
    sys.exit(0 if result.wasSuccessful() else 1)


if __name__ == "__main__":
    main()
