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
  BENCHMARK=$build_dir/devel/lib/projection_collision_avoidance/benchmark_methods
fi
test -x "$BENCHMARK" || {
  echo "comparison cpu: no benchmark_methods at $BENCHMARK (libbenchmark-dev installed?)" >&2
  exit 1
}

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$BENCHMARK" --benchmark_repetitions="$reps" --benchmark_min_time="$min_time" \
  --benchmark_format=json >"$work/benchmark.json"
/usr/bin/python3 "$here/comparison_cpu.py" "$work/benchmark.json" "$out" --date "$(date +%F)" \
  --reps "$reps" --min-time "$min_time"
echo "comparison cpu: wrote $out/comparison_cpu.csv, comparison_cpu.md"
