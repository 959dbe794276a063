#!/usr/bin/python3
"""The table of experiments/link/run.sh from its results directory: per transport and condition,
the latency (receipt - stamp at the follower host, percentiles in ms), the measurements the plant
sent in the window (seen by the probe on its own host), those lost on the link (sent, never seen
at the follower host), those that arrived out of order, and the follower's refused measurements
over the run (FollowerStatus.rejected_measurements)."""

import argparse
import csv
import math
import pathlib
import re

TRANSPORTS = ("tcp", "udp")
CONDITIONS = ("none", "dropout", "latency", "flood")


def read_arrivals(path):
    rows = []
    for line in path.read_text().split("\n"):
        if line.strip():
            stamp, receipt = line.split()
            rows.append((int(stamp), int(receipt)))
    return rows


def percentile(values, q):
    """Nearest rank."""
    ordered = sorted(values)
    return ordered[max(0, min(len(ordered) - 1, math.ceil(q * len(ordered)) - 1))]


def flood_rate(path):
    if not path.exists():
        return float("nan")
    match = re.search(r"link_flood: \w+ \d+ messages, ([0-9.]+) Hz", path.read_text())
    return float(match.group(1)) if match else float("nan")


def summarise(directory):
    sent = read_arrivals(directory / "world_host.txt")
    seen = read_arrivals(directory / "follower_host.txt")
    sent_stamps = {s for s, _ in sent}
    seen_stamps = [s for s, _ in seen]
    latencies = [1e-6 * (r - s) for s, r in seen]
    out_of_order = sum(1 for a, b in zip(seen_stamps, seen_stamps[1:]) if b <= a)
    rejected_file = directory / "rejected.txt"
    rejected = rejected_file.read_text().strip() if rejected_file.exists() else ""
    return {
        "sent": len(sent),
        "received": len(seen),
        "lost": len(sent_stamps - set(seen_stamps)),
        "out_of_order": out_of_order,
        "p50_ms": percentile(latencies, 0.50) if latencies else float("nan"),
        "p99_ms": percentile(latencies, 0.99) if latencies else float("nan"),
        "max_ms": max(latencies) if latencies else float("nan"),
        "refused": rejected or "n/a",
        "flood_sent_hz": flood_rate(directory / "flood_pub.log"),
        "flood_received_hz": flood_rate(directory / "flood_sub.log"),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("results")
    parser.add_argument("--csv", required=True)
    parser.add_argument("--flood", default="", help="what the flood was, for the table's note")
    args = parser.parse_args()
    rows = []
    for transport in TRANSPORTS:
        for condition in CONDITIONS:
            directory = pathlib.Path(args.results) / f"{transport}_{condition}"
            rows.append({"transport": transport, "condition": condition, **summarise(directory)})
    with open(args.csv, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        writer.writeheader()
        writer.writerows(rows)
    print("| transport | condition | p50 (ms) | p99 (ms) | max (ms) | sent | lost | out of order | refused |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['transport']} | {r['condition']} | {r['p50_ms']:.3f} | {r['p99_ms']:.3f} | "
              f"{r['max_ms']:.3f} | {r['sent']} | {r['lost']} | {r['out_of_order']} | {r['refused']} |")
    for r in rows:
        if r["condition"] == "flood":
            print(f"flood ({args.flood}) with {r['transport']}: sent {r['flood_sent_hz']:.0f} Hz, "
                  f"received {r['flood_received_hz']:.0f} Hz")
    print(f"CSV: {args.csv}")


if __name__ == "__main__":
    main()
