#!/usr/bin/env bash
# Every performance figure of doc/performance_summary.md, side by side in one run:
#   1. Google Benchmark: one control step in 1-D, 2-D, 3-D (inside the bound and held on it by
#      the projection), heap allocations and flops per step; whole Run 2 in process;
#   2. callgrind: instructions per control step (load-independent);
#   3. cf_sim against the SciPy LSODA reference, whole processes (solver_comparison.py, beside
#      this script);
#   4. the ROS follower at 1 kHz on real time next to a bare roscpp relay
#      (experiments/ros_latency/run.sh, into doc/ros_latency.csv), unless --skip-ros (then the
#      figures of its last run in doc/ros_latency.csv);
#   5. platoon scale: experiments/formation_scale/run.sh with --with-scale (18 min), else the
#      figures of its last run in doc/formation_scale.md.
# Writes the raw figures to doc/performance_data/, then doc/performance.md and the table between
# the performance markers of doc/performance_summary.md; --report-only renders those two from the raw figures.
# Usage: experiments/performance/run.sh [--reps N] [--ros-runs N] [--ros-duration S]
#          [--skip-ros] [--with-scale] [--no-summary] [--report-only]
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
build_dir=${BUILD_DIR:-$root/build}
reps=10
ros_runs=3
ros_duration=60
skip_ros=0
with_scale=0
update_summary=1
report_only=0
while [ $# -gt 0 ]; do
  case "$1" in
    --reps) reps=$2; shift 2 ;;
    --ros-runs) ros_runs=$2; shift 2 ;;
    --ros-duration) ros_duration=$2; shift 2 ;;
    --skip-ros) skip_ros=1; shift ;;
    --with-scale) with_scale=1; shift ;;
    --no-summary) update_summary=0; shift ;;
    --report-only) report_only=1; shift ;;
    *) echo "usage: $0 [--reps N] [--ros-runs N] [--ros-duration S] [--skip-ros] [--with-scale] [--no-summary] [--report-only]" >&2
       exit 2 ;;
  esac
done

data=$root/doc/performance_data
mkdir -p "$data"
if [ "$report_only" = 0 ]; then
BUILD_DIR=$build_dir "$root/scripts/build.sh" >/dev/null
bin=$build_dir/devel/lib/projection_collision_avoidance
for tool in benchmark_follower_step step_instructions cf_sim; do
  test -x "$bin/$tool" || { echo "$tool was not built (libbenchmark-dev installed?)" >&2; exit 1; }
done
command -v valgrind >/dev/null || { echo "valgrind is needed for the instruction counts" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "$reps" >"$data/repetitions"
date +%F >"$data/date"

echo "== 1/5 Google Benchmark ($reps repetitions)" >&2
"$bin/benchmark_follower_step" --benchmark_repetitions="$reps" \
  --benchmark_report_aggregates_only=true --benchmark_format=json >"$data/benchmark.json"

echo "== 2/5 callgrind instructions per step" >&2
: >"$data/instructions.csv"
for axes in 1 2 3; do
  for regime in inside outside; do
    counts=()
    for steps in 1000 11000; do
      valgrind --tool=callgrind --callgrind-out-file="$work/callgrind.out" \
        "$bin/step_instructions" "$axes" "$steps" "$regime" >/dev/null 2>"$work/callgrind.log"
      counts+=("$(sed -n 's/.*Collected : \([0-9]*\).*/\1/p' "$work/callgrind.log")")
    done
    echo "$axes,$regime,${counts[0]},${counts[1]}" >>"$data/instructions.csv"
  done
done

echo "== 3/5 cf_sim against SciPy LSODA ($reps repetitions)" >&2
/usr/bin/python3 "$here/solver_comparison.py" --cf-sim "$bin/cf_sim" --reps "$reps" \
  --json "$data/solvers.json" >/dev/null

if [ "$skip_ros" = 0 ]; then
  echo "== 4/5 ROS follower at 1 kHz ($ros_runs runs of $ros_duration s per setting)" >&2
  bash "$root/experiments/ros_latency/run.sh" --runs "$ros_runs" --duration "$ros_duration" \
    --realtime --follower-thread --csv "$root/doc/ros_latency.csv" >/dev/null
fi

if [ "$with_scale" = 1 ]; then
  echo "== 5/5 platoon scale (experiments/formation_scale/run.sh)" >&2
  bash "$root/experiments/formation_scale/run.sh" >/dev/null
fi

fi

summary_args=()
if [ "$update_summary" = 1 ]; then
  summary_args=(--summary "$root/doc/performance_summary.md")
fi
/usr/bin/python3 "$here/performance_report.py" --benchmark "$data/benchmark.json" \
  --instructions "$data/instructions.csv" --solvers "$data/solvers.json" \
  --ros-csv "$root/doc/ros_latency.csv" \
  --scale "$root/doc/formation_scale.md" --reps "$(cat "$data/repetitions")" --date "$(cat "$data/date" 2>/dev/null || date +%F)" --out "$root/doc/performance.md" \
  "${summary_args[@]}"
