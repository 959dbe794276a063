#!/usr/bin/python3
"""Print cf_sim's summary line for a rosbag of the demo.

Usage::

    bag_summary.py RUN.bag

Reads the follower's status (/follower/status, projection_collision_avoidance/FollowerStatus;
the only topic of that type if the bag has no /follower/status) and prints one line in the
format of cf_sim (doc/cf_sim.md, 'The summary line')::

    max_xi=... max_xi_hat=... xi_max=... min_separation=... time_outside=... recorded_s=...

  max_xi, max_xi_hat  largest xi_norm and xi_hat_norm over the status messages
  xi_max              the status's xi_max (the last one; a warning if it changed)
  min_separation      smallest status separation
  time_outside        total time of the status intervals [t_k, t_(k+1)) (header stamps) with
                      xi_norm > xi_max; the last message counts for the median interval, as
                      cf_sim counts whole control periods
  recorded_s          the time span over which the status messages were recorded (bag record
                      times, last - first). rosbag record stamps with ros::Time::now(), so under
                      simulated time (use_sim_time, the demo's default) this is simulated time,
                      not the wall-clock time of the run.

Numbers are printed like cf_sim's (printf "%.9g"). Exit codes: 0 done, 1 bag unreadable or
without status messages, 2 usage. Messages are deserialised from the definitions stored in the
bag, so the package's generated Python messages need not be importable. Run with
/usr/bin/python3 (Debian's python3-rosbag).
"""

from __future__ import annotations

import argparse
import sys

PROG = "bag_summary"
STATUS_TOPIC = "/follower/status"
STATUS_TYPE = "projection_collision_avoidance/FollowerStatus"


class SummaryError(Exception):
    pass


def status_topic(bag, path):
    topics = bag.get_type_and_topic_info().topics
    if STATUS_TOPIC in topics:
        return STATUS_TOPIC
    same = sorted(t for t, info in topics.items() if info.msg_type == STATUS_TYPE)
    if len(same) == 1:
        return same[0]
    if same:
        raise SummaryError(f"{path}: no {STATUS_TOPIC}, and several {STATUS_TYPE} topics "
                           f"({', '.join(same)})")
    raise SummaryError(f"{path}: no {STATUS_TOPIC} ({STATUS_TYPE}) messages")


def stamp_of(msg, record_time):
    stamp = msg.header.stamp
    if stamp.secs == 0 and stamp.nsecs == 0:
        return record_time.to_sec()
    return stamp.to_sec()


def summarize(path):
    """The summary values of the bag at path, as a dict (cf_sim's keys, in order)."""
    try:
        import rosbag
    except ImportError as exc:
        raise SummaryError(f"reading a bag needs the rosbag Python module (python3-rosbag; "
                           f"run with /usr/bin/python3): {exc}") from None
    try:
        bag = rosbag.Bag(path)
    except rosbag.ROSBagException as exc:
        raise SummaryError(f"{path}: not a readable bag ({exc})") from None
    rows = []  # (stamp, xi_norm, xi_hat_norm, xi_max, separation, record time)
    with bag:
        topic = status_topic(bag, path)
        for _, msg, rec in bag.read_messages(topics=[topic], raw=False):
            rows.append((stamp_of(msg, rec), msg.xi_norm, msg.xi_hat_norm, msg.xi_max,
                         msg.distance, rec.to_sec()))
    if not rows:
        raise SummaryError(f"{path}: {topic} has no messages")

    rows.sort(key=lambda r: r[0])
    stamps = [r[0] for r in rows]
    intervals = [b - a for a, b in zip(stamps, stamps[1:])]
    if intervals:
        positive = sorted(d for d in intervals if d > 0)
        last = positive[len(positive) // 2] if positive else 0.0
    else:
        last = 0.0
    intervals.append(last)

    xi_max_values = {r[3] for r in rows}
    if len(xi_max_values) > 1:
        print(f"{PROG}: warning: xi_max changed during the run "
              f"({min(xi_max_values):.9g} to {max(xi_max_values):.9g}); reporting the last",
              file=sys.stderr)
    records = [r[5] for r in rows]
    return {
        "max_xi": max(r[1] for r in rows),
        "max_xi_hat": max(r[2] for r in rows),
        "xi_max": rows[-1][3],
        "min_separation": min(r[4] for r in rows),
        "time_outside": sum(d for r, d in zip(rows, intervals) if r[1] > r[3]),
        "recorded_s": max(records) - min(records),
    }


def format_summary(values):
    return " ".join(f"{key}={value:.9g}" for key, value in values.items())


def main(argv=None):
    ap = argparse.ArgumentParser(
        prog="bag_summary.py",
        description="Print cf_sim's summary line (max_xi, max_xi_hat, xi_max, min_separation, "
                    "time_outside, recorded_s) for a rosbag of the demo, from /follower/status.")
    ap.add_argument("bag", metavar="RUN.bag", help="bag recorded by demo.launch record:=true")
    args = ap.parse_args(argv)
    try:
        values = summarize(args.bag)
    except (OSError, SummaryError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 1
    print(format_summary(values))
    return 0


if __name__ == "__main__":
    sys.exit(main())
