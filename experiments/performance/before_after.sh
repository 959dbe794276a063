#!/usr/bin/env bash
# Two builds side by side (e.g. the commit before a change and after it): the control step of
# Google Benchmark (median of REPS runs, the builds in turn) and the ROS follower at 1 kHz
# (experiments/ros_latency/run.sh: keep-awake, and the real-time control thread), the builds
# measured in turn, run by run. Prints Markdown tables; raw figures go to OUT.
# Usage: experiments/performance/before_after.sh BEFORE_BUILD AFTER_BUILD OUT
#          [--runs N] [--duration S] [--reps R]
#   BEFORE_BUILD, AFTER_BUILD  standalone build directories (scripts/build.sh with BUILD_DIR),
#                              each built from its own checkout
#   --runs 2  --duration 30  --reps 5  --report-only (the tables from OUT's figures)
# Timing-sensitive: run it on a quiet machine; the control-thread setting needs root.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
[ $# -ge 3 ] || { sed -n '2,11p' "${BASH_SOURCE[0]}"; exit 2; }
builds=("$1" "$2")
labels=(before after)
out=$3
shift 3
runs=2
duration=30
reps=5
report_only=0
while [ $# -gt 0 ]; do
  case $1 in
    --runs) runs=$2; shift 2 ;;
    --duration) duration=$2; shift 2 ;;
    --reps) reps=$2; shift 2 ;;
    --report-only) report_only=1; shift ;;
    *) echo "before_after: unknown argument $1" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"

if [ "$report_only" = 0 ]; then
# The two builds' benchmarks in turn, one repetition each, REPS times: a machine that drifts
# (frequency, other load) moves both alike.
for rep in $(seq 1 "$reps"); do
  for i in 0 1; do
    bin=${builds[$i]}/devel/lib/projection_collision_avoidance
    "$bin/benchmark_follower_step" --benchmark_format=json \
      >"$out/${labels[$i]}_benchmark_$rep.json"
  done
done
for run in $(seq 1 "$runs"); do
  for i in 0 1; do
    BUILD_DIR=${builds[$i]} bash "$root/experiments/ros_latency/run.sh" --runs 1 \
      --duration "$duration" --only keep-awake,follower-thread \
      --csv "$out/${labels[$i]}_latency_$run.csv" >"$out/${labels[$i]}_latency_$run.md"
  done
done
fi

/usr/bin/python3 - "$out" "$runs" "$reps" <<'EOF'
import csv, glob, json, statistics, sys
out, runs = sys.argv[1], int(sys.argv[2])
def bench(label):
    times = {}
    for path in sorted(glob.glob(f"{out}/{label}_benchmark_*.json")):
        for b in json.load(open(path))["benchmarks"]:
            times.setdefault(b["run_name"], ([], b["time_unit"]))[0].append(b["real_time"])
    return {name: (statistics.median(t), unit) for name, (t, unit) in times.items()}
before, after = bench("before"), bench("after")
print(f"| benchmark (median of {sys.argv[3]}, in turn) | before | after | after / before |")
print("|---|---|---|---|")
for name, (b, unit) in before.items():
    if name in after:
        a = after[name][0]
        print(f"| `{name}` | {b:.4g} {unit} | {a:.4g} {after[name][1]} | {a / b:.3f} |")
print()
rows = {}
for label in ("before", "after"):
    for run in range(1, runs + 1):
        for row in csv.DictReader(open(f"{out}/{label}_latency_{run}.csv")):
            rows.setdefault((row["setting"], label), []).append(row)
wanted = ["relay_p50_us", "relay_p99_us", "follower_timer_p50_us", "follower_timer_p99_us",
          "follower_measurement_p50_us", "follower_measurement_p99_us",
          "follower_timer_missed_percent", "follower_timer_late_percent",
          "follower_measurement_missed_percent", "follower_measurement_late_percent"]
print("Medians over the runs; latency from the measurement's publication (µs), missed and late "
      "control periods (% of the periods).")
print()
print("| setting | build | runs | " + " | ".join(wanted) + " |")
print("|---|---|---|" + "---|" * len(wanted))
for (setting, label), group in sorted(rows.items(), key=lambda kv: (kv[0][0], kv[0][1] != "before")):
    medians = []
    for k in wanted:
        values = [float(r[k]) for r in group if r[k] not in ("", "nan")]
        medians.append(f"{statistics.median(values):.3f}" if values else "-")
    print(f"| {setting} | {label} | {len(group)} | " + " | ".join(medians) + " |")
EOF
