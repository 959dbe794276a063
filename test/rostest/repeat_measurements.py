#!/usr/bin/python3
"""A hostile sender for rostests: republishes each RelativeMeasurement it hears on `input` to
`output` ~copies times, the k-th copy (k = 0 .. copies - 1) stamped ~spacing_us * k microseconds
after the original, as a sender that repeats its messages, or a sensor much faster than the
control rate, would. ~seed (optional, >= 0) adds a seeded random extra offset of up to
~spacing_us / 2 to each copy after the first, so that the copies are not evenly spaced.

Parameters: ~copies (int >= 1), ~spacing_us (> 0), ~seed (int; < 0: no random offset)."""

import copy
import random

import rospy
from projection_collision_avoidance.msg import RelativeMeasurement


def main():
    rospy.init_node("repeat_measurements")
    copies = int(rospy.get_param("~copies", 5))
    spacing = float(rospy.get_param("~spacing_us", 1.0))
    seed = int(rospy.get_param("~seed", -1))
    if copies < 1:
        rospy.logfatal("~copies must be at least 1, not %d", copies)
        return
    if not spacing > 0.0:
        rospy.logfatal("~spacing_us must be > 0, not %s", spacing)
        return
    rng = random.Random(seed) if seed >= 0 else None
    publisher = rospy.Publisher("output", RelativeMeasurement, queue_size=1000, tcp_nodelay=True)

    def on_measurement(msg):
        offset_ns = 0
        for k in range(copies):
            out = copy.copy(msg)
            out.header = copy.copy(msg.header)
            if k > 0:
                extra = rng.uniform(0.0, 0.5 * spacing) if rng is not None else 0.0
                offset_ns = max(offset_ns + 1, int(round(1e3 * (spacing * k + extra))))
            out.header.stamp = msg.header.stamp + rospy.Duration(0, offset_ns)
            publisher.publish(out)

    rospy.Subscriber("input", RelativeMeasurement, on_measurement, queue_size=1000,
                     tcp_nodelay=True)
    rospy.spin()


if __name__ == "__main__":
    main()
