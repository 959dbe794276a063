#!/usr/bin/env bash
# CPU per follower step of each method of doc/comparison.md: runs benchmark_methods
# (test/benchmark/benchmark_methods.cpp: the baseline law, the CF estimator and tracker, and the
# barrier filter slack and binding, 1-D to 3-D) with REPS repetitions, takes the medians and
# fails (exit 1) unless every case ran in its regime and allocated nothing. Writes OUT_DIR
# (default doc/) comparison_cpu.csv and comparison_cpu.md; with OUT_DIR = doc/ the table is also
# placed in comparison.md between its comparison-cpu markers.
# Usage: experiments/comparison/cpu.sh [--reps N] [--min-time S] [OUT_DIR]   (about 30 s)
# Builds first (BUILD_DIR as for scripts/build.sh), unless BENCHMARK=path/to/benchmark_methods
# is given.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
# shellcheck source=experiments/common/benchmark_run.bash
source "$root/experiments/common/benchmark_run.bash"
cpu_arguments "$root" "$@"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
run_benchmark "comparison cpu" benchmark_methods "$root" "$work/benchmark.json"
/usr/bin/python3 "$here/comparison_cpu.py" "$work/benchmark.json" "$out" --date "$(date +%F)" \
  --reps "$reps" --min-time "$min_time"
echo "comparison cpu: wrote $out/comparison_cpu.csv, comparison_cpu.md"
