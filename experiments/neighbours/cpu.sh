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
# shellcheck source=experiments/common/benchmark_run.bash
source "$root/experiments/common/benchmark_run.bash"
cpu_arguments "$root" "$@"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "neighbours cpu: $reps repetitions of every case, at least $min_time s each" >&2
run_benchmark "neighbours cpu" benchmark_neighbours "$root" "$work/benchmark.json"
/usr/bin/python3 "$here/neighbours_cpu.py" "$work/benchmark.json" "$out" --date "$(date +%F)" \
  --min-time "$min_time"
echo "neighbours cpu: wrote $out/neighbours_cpu.csv, neighbours_cpu.md, neighbours_cpu.png"
