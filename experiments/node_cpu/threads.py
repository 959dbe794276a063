#!/usr/bin/python3
"""The follower's CPU per tick by thread, from node_cpu.py's JSON lines, as a Markdown table.

  threads.py R.jsonl [R2.jsonl ...]

For each measurement (build or label, rate), the follower's process (follower_node, or the bare
relay measurement_relay of node_cpu.py --floor), in µs of CPU per tick (schedstat):
  - main: the process's first thread (lowest id), which runs ros::spin();
  - tick: the threads named "follower ticks" or "tick <index>";
  - network: the busiest of the others, roscpp's PollManager thread (it receives every message
    and writes every message to another process);
  - other: the rest (roscpp's timer and rosout threads, XML-RPC, the spinners of older builds).
"""

import json
import sys

FOLLOWERS = ("follower_node", "measurement_relay")


def split(threads):
    """{main, tick, network, other: seconds} of one process's {"name/tid": seconds}."""
    by_tid = sorted((int(key.rsplit("/", 1)[1]), key.rsplit("/", 1)[0], s)
                    for key, s in threads.items())
    parts = {"main": by_tid[0][2], "tick": 0.0, "network": 0.0, "other": 0.0}
    rest = []
    for _, name, seconds in by_tid[1:]:
        if name == "follower ticks" or name.startswith("tick "):
            parts["tick"] += seconds
        else:
            rest.append(seconds)
    rest.sort(reverse=True)
    if rest:
        parts["network"] = rest[0]
        parts["other"] = sum(rest[1:])
    return parts


def main(paths):
    print("| build | control rate | process | per tick | network thread | main thread | "
          "tick thread | other threads |")
    print("|---|---:|---|---:|---:|---:|---:|---:|")
    for path in paths:
        with open(path) as f:
            for line in f:
                r = json.loads(line)
                ticks = r["tick_rate"] * r["window_s"]
                for node in FOLLOWERS:
                    if node not in r["nodes"]:
                        continue
                    n = r["nodes"][node]
                    parts = split(n["threads_s"])
                    us = {k: 1e6 * v / ticks for k, v in parts.items()}
                    print("| %s | %g Hz | %s | %.1f µs | %.1f | %.1f | %.1f | %.1f |" % (
                        r.get("label", ""), r["rate"], node, n["us_per_tick_sched"],
                        us["network"], us["main"], us["tick"], us["other"]))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
