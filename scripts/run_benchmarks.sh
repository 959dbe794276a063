#!/usr/bin/env bash
# Runs the Google Benchmark target (one control step in 1-D, 2-D, 3-D; a whole cf_sim run of
# the paper's Run 2) with repetitions and prints the medians as a Markdown table.
# Usage: scripts/run_benchmarks.sh [repetitions]   (BUILD_DIR as for scripts/build.sh)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${BUILD_DIR:-$root/build}
repetitions=${1:-10}
BUILD_DIR=$build_dir "$root/scripts/build.sh" >/dev/null
bench=$build_dir/devel/lib/projection_collision_avoidance/benchmark_follower_step
test -x "$bench" || { echo "benchmark_follower_step was not built (libbenchmark-dev?)"; exit 1; }

json=$(mktemp)
trap 'rm -f "$json"' EXIT
"$bench" --benchmark_repetitions="$repetitions" --benchmark_report_aggregates_only=true \
  --benchmark_format=json >"$json"
/usr/bin/python3 - "$json" "$repetitions" <<'PY'
import json, sys
data = json.load(open(sys.argv[1]))
ctx = data["context"]
print(f"{ctx['num_cpus']} CPUs at {ctx['mhz_per_cpu']} MHz, median of {sys.argv[2]} repetitions")
print()
print("| benchmark | median time | median CPU |")
print("|---|---|---|")
for b in data["benchmarks"]:
    if b.get("aggregate_name") != "median":
        continue
    name = b["run_name"]
    print(f"| `{name}` | {b['real_time']:.3g} {b['time_unit']} | {b['cpu_time']:.3g} {b['time_unit']} |")
PY
