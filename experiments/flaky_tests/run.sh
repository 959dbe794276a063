#!/usr/bin/env bash
# Runs the whole ctest suite (gtests, rostests, Python checks) RUNS times in a row on a loaded
# machine and tabulates every failure: flaky_tests.py writes doc/flaky_tests.csv (one row per run
# and failing test, with the failure's first lines) and the table of doc/testing.md.
# Usage: experiments/flaky_tests/run.sh [--runs N] [--load CPUS] [--jobs J] [--build DIR]
#          [--out CSV] [--no-doc]
#   --runs N     runs of the suite (default 5)
#   --load CPUS  stress-ng workers busy on the CPU the whole time (default: one per core; 0: none)
#   --jobs J     ctest -j J, as scripts/test.sh runs it (default: the cores)
#   --build DIR  a build folder with its tests built (default: a colcon workspace built as
#                scripts/test.sh builds it, in $TMPDIR/projection_collision_avoidance-flaky)
#   --multihost  also the multi-host cases (root) in each run
# Each run's ctest log and JUnit files are kept in out/flaky_tests/run_<i>/.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
runs=5
load=$(nproc)
jobs=$(nproc)
build=""
csv=$root/doc/flaky_tests.csv
doc=true
multihost=false
while [[ $# -gt 0 ]]; do
  case $1 in
    --runs) runs=$2; shift 2 ;;
    --load) load=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --out) csv=$2; shift 2 ;;
    --no-doc) doc=false; shift ;;
    --multihost) multihost=true; shift ;;
    *) echo "unknown argument $1" >&2; exit 2 ;;
  esac
done
if [[ -z $build ]]; then
  # A colcon workspace outside the package, as scripts/test.sh builds it; kept for the next run.
  workspaces=${TMPDIR:-/tmp}/projection_collision_avoidance-flaky
  build=$workspaces/colcon/build/projection_collision_avoidance
  if [[ -f $build/CTestTestfile.cmake ]]; then
    echo "flaky_tests: rebuilding what changed in $workspaces/colcon"
    make -C "$build" -j"$(nproc)" all tests >"$workspaces/colcon/rebuild.log" 2>&1 || {
      tail -40 "$workspaces/colcon/rebuild.log"; echo "flaky_tests: the build failed"; exit 1; }
  else
    echo "flaky_tests: building the package and its tests in $workspaces/colcon"
    build=$("$root/scripts/workspace.sh" colcon "$workspaces" --tests)
  fi
fi
out=$root/out/flaky_tests
rm -rf "$out"
mkdir -p "$out"

stress=""
stop_stress() { [[ -n $stress ]] && kill "$stress" 2>/dev/null && wait "$stress" 2>/dev/null || true; }
trap stop_stress EXIT
if [[ $load -gt 0 ]]; then
  stress-ng --cpu "$load" --timeout 0 --quiet &
  stress=$!
fi
echo "flaky_tests: $runs runs of ctest -j$jobs in $build, with $load stress-ng CPU workers"
for run in $(seq "$runs"); do
  dir=$out/run_$run
  mkdir -p "$dir"
  rm -rf "$build/test_results"
  start=$SECONDS
  (cd "$build" && ctest -j"$jobs" --output-on-failure >"$dir/ctest.log" 2>&1) || true
  if [[ $multihost == true ]]; then
    MULTIHOST_JOBS=$jobs "$root/test/multihost/run_all.sh" "$build" \
      "$build/test_results/projection_collision_avoidance" >"$dir/multihost.log" 2>&1 || true
  fi
  cp -r "$build/test_results" "$dir/test_results"
  echo "run $run: $((SECONDS - start)) s; $(grep -E 'tests passed' "$dir/ctest.log" || echo 'no summary')"
done
stop_stress
args=(--out "$csv" --runs "$runs" --load "$load" --jobs "$jobs")
[[ $doc == true ]] && args+=(--update "$root/doc/testing.md")
/usr/bin/python3 "$here/flaky_tests.py" "$out" "${args[@]}"
