#!/usr/bin/python3
"""The table of CPU per follower step of each method (benchmark_methods' JSON): median CPU time
over the repetitions, heap allocations per step. Exits 1 when a case is missing, skipped (not in
its regime) or allocated.
Usage: comparison_cpu.py BENCHMARK.json OUT_DIR --date D --reps N --min-time S
"""

import argparse
import csv
import json
import os
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "common"))
from doc_block import replace_block  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CASES = [("BM_Baseline", "baseline law (the CF estimator running, not acting)", (1, 2, 3)),
         ("BM_CfTracker", "CF estimator and tracker", (1, 2, 3)),
         ("BM_BarrierSlack", "barrier filter, slack (target at its slot)", (1, 2, 3)),
         ("BM_BarrierBinding", "barrier filter, binding (target 1.2 m to the side)", (2, 3))]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("json")
    ap.add_argument("out")
    ap.add_argument("--date", required=True)
    ap.add_argument("--reps", type=int, required=True)
    ap.add_argument("--min-time", required=True)
    args = ap.parse_args()
    data = json.load(open(args.json))
    medians, allocations, errors = {}, {}, []
    for b in data["benchmarks"]:
        m = re.match(r"(BM_\w+)<DoubleIntegrator(\d)D>", b["name"])
        if not m:
            continue
        key = (m.group(1), int(m.group(2)))
        if b.get("error_occurred"):
            errors.append(f"{b['name']}: {b.get('error_message')}")
        if b.get("aggregate_name") == "median":
            medians[key] = b["cpu_time"]
        if b.get("run_type") == "iteration":
            allocations[key] = max(allocations.get(key, 0.0), b.get("allocations", 0.0))
    for name, _, axes in CASES:
        for k in axes:
            if (name, k) not in medians:
                errors.append(f"{name} {k}-D: no median")
            elif allocations.get((name, k), 0.0) != 0.0:
                errors.append(f"{name} {k}-D: {allocations[(name, k)]} allocations per step")
    if errors:
        sys.exit("comparison cpu: " + "; ".join(errors))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "comparison_cpu.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["method", "axes", "median_cpu_ns", "allocations_per_step"])
        for name, _, axes in CASES:
            for k in axes:
                w.writerow([name, k, f"{medians[(name, k)]:.1f}", 0])
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    lines = [f"Made by `bash experiments/comparison/cpu.sh` on {args.date}: ns per follower step, "
             f"median CPU time of {args.reps} repetitions of at least {args.min_time} s each, "
             f"{os.cpu_count()} CPUs, load average {load}. Heap allocations per step: 0 in every "
             "case.", "", "| method | 1-D | 2-D | 3-D |", "|---|---:|---:|---:|"]
    for name, label, axes in CASES:
        cells = [f"{medians[(name, k)]:.0f}" if k in axes else "—" for k in (1, 2, 3)]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    text = "\n".join(lines) + "\n"
    (out / "comparison_cpu.md").write_text(text)
    if out.resolve() == (ROOT / "doc").resolve():
        replace_block(ROOT / "doc" / "comparison.md", "<!-- comparison cpu begin -->",
                      "<!-- comparison cpu end -->", text)


if __name__ == "__main__":
    main()
