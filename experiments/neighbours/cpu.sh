#!/usr/bin/env bash
# CPU per follower step against the number of sensed neighbours: runs benchmark_neighbours
# (test/benchmark/benchmark_neighbours.cpp: the step with formation.neighbours, crowds none, far,
# arc and ring, max_neighbours 8 and 32, N = 1 .. 64 sensed agents, 2-D and 3-D) with REPS
# repetitions, takes the medians and fails (exit 1) unless every case ran and allocated nothing.
# Writes OUT_DIR (default doc/) neighbours_cpu.csv, neighbours_cpu.md and neighbours_cpu.png; with
# OUT_DIR = doc/ the table is also placed in formations.md and a line in performance_summary.md,
# each between their neighbours-cpu markers.
# Usage: experiments/neighbours/cpu.sh [--reps N] [--min-time S] [OUT_DIR]
#   (about 2 minutes with the defaults, 5 repetitions of at least 0.1 s per case).
# Builds first (BUILD_DIR as for scripts/build.sh), unless BENCHMARK=path/to/benchmark_neighbours
# is given.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
reps=5
min_time=0.1
out=$root/doc
while [ $# -gt 0 ]; do
  case "$1" in
    --reps) reps=$2; shift 2 ;;
    --min-time) min_time=$2; shift 2 ;;
    -*) echo "usage: $0 [--reps N] [--min-time S] [OUT_DIR]" >&2; exit 2 ;;
    *) out=$1; shift ;;
  esac
done

if [[ -z ${BENCHMARK:-} ]]; then
  build_dir=${BUILD_DIR:-$root/build}
  BUILD_DIR=$build_dir "$root/scripts/build.sh" >/dev/null
  BENCHMARK=$build_dir/devel/lib/projection_collision_avoidance/benchmark_neighbours
fi
test -x "$BENCHMARK" || {
  echo "neighbours cpu: no benchmark_neighbours at $BENCHMARK (libbenchmark-dev installed?)" >&2
  exit 1
}

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "neighbours cpu: $reps repetitions of every case, at least $min_time s each" >&2
"$BENCHMARK" --benchmark_repetitions="$reps" --benchmark_min_time="$min_time" \
  --benchmark_format=json >"$work/benchmark.json"
/usr/bin/python3 "$here/neighbours_cpu.py" "$work/benchmark.json" "$out" --date "$(date +%F)" \
  --min-time "$min_time"
echo "neighbours cpu: wrote $out/neighbours_cpu.csv, neighbours_cpu.md, neighbours_cpu.png"
