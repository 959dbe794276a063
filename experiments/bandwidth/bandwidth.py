#!/usr/bin/python3
"""Bytes per second that a follower sends and receives, per topic (experiments/bandwidth/run.sh).

Subscribes to each topic as rospy.AnyMsg (the serialised bytes, not decoded) for --duration
seconds of wall time once every topic has published, and prints a Markdown table: topic,
direction, messages/s, payload bytes/s and bytes/s on the wire with TCPROS's 4-byte length
prefix per message (IP and TCP headers not counted). Run it beside a launch of pair.launch.
"""

import argparse
import sys
import threading
import time

import rospy

TOPICS = [  # (topic, direction seen from the follower)
    ("/follower/relative_measurement", "in"),
    ("/leader/broadcast", "in"),
    ("/follower/command", "out"),
    ("/follower/broadcast", "out"),
    ("/follower/status", "out"),
    ("/follower/markers", "out"),
    ("/diagnostics", "out (all nodes)"),
]
TCPROS_PREFIX = 4  # bytes of length before each message


class Counter:
    def __init__(self):
        self.lock = threading.Lock()
        self.counting = False
        self.messages = 0
        self.payload = 0
        self.seen = False

    def __call__(self, msg):
        with self.lock:
            self.seen = True
            if self.counting:
                self.messages += 1
                self.payload += len(msg._buff)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=20.0, help="wall seconds counted")
    parser.add_argument("--label", default="", help="a first column for every row")
    parser.add_argument("--wait", type=float, default=60.0, help="wall seconds to wait for topics")
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node("bandwidth_probe", anonymous=True)
    counters = {}
    for topic, _ in TOPICS:
        counters[topic] = Counter()
        rospy.Subscriber(topic, rospy.AnyMsg, counters[topic], queue_size=10000,
                         tcp_nodelay=True)
    required = [t for t, _ in TOPICS if t not in ("/follower/markers", "/diagnostics")]
    end = time.monotonic() + args.wait
    while not all(counters[t].seen for t in required):
        if time.monotonic() > end or rospy.is_shutdown():
            missing = [t for t in required if not counters[t].seen]
            sys.exit(f"bandwidth: no messages on {', '.join(missing)}")
        time.sleep(0.1)
    for counter in counters.values():
        with counter.lock:
            counter.counting = True
    start = time.monotonic()
    time.sleep(args.duration)
    elapsed = time.monotonic() - start
    total_in = total_out = 0.0
    print("| setting | topic | direction | messages/s | payload (B/s) | on the wire (B/s) |")
    print("|---|---|---|---|---|---|")
    for topic, direction in TOPICS:
        c = counters[topic]
        with c.lock:
            rate = c.messages / elapsed
            payload = c.payload / elapsed
        wire = payload + TCPROS_PREFIX * rate
        if direction == "in":
            total_in += wire
        elif direction == "out":
            total_out += wire
        print(f"| {args.label} | `{topic}` | {direction} | {rate:.1f} | {payload:.0f} | {wire:.0f} |")
    print(f"| {args.label} | total | in | | | {total_in:.0f} |")
    print(f"| {args.label} | total | out (follower's own topics) | | | {total_out:.0f} |")


if __name__ == "__main__":
    main()
