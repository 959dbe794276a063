#!/usr/bin/env bash
# The everyday subset of scripts/test.sh: the package built in one colcon workspace (kept between
# runs, so a rebuild compiles only what changed) and its ctest suite, two at a time: the gtests,
# the rostests and the Python checks. Not the multi-host cases, the other two workspace routes or
# the sanitizer build: CI (scripts/test.sh) runs those.
# Usage: scripts/quick_test.sh [ctest arguments...]   e.g. -L gtest, -R paper_run
# Environment: QUICK_TEST_DIR (default $TMPDIR/projection_collision_avoidance-quick).
# Assumes scripts/setup.sh has run.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
package=projection_collision_avoidance
dir=${QUICK_TEST_DIR:-${TMPDIR:-/tmp}/$package-quick}
build=$dir/colcon/build/$package
start=$SECONDS
if [[ -f $build/CTestTestfile.cmake ]]; then
  # The workspace exists: build what changed (CMake reconfigures itself when it must).
  make -C "$build" -j"$(nproc)" all tests >"$dir/colcon/rebuild.log" 2>&1 || {
    tail -40 "$dir/colcon/rebuild.log"; echo "quick_test: the build failed"; exit 1; }
else
  build=$("$root/scripts/workspace.sh" colcon "$dir" --tests)
fi
echo "quick_test: built in $((SECONDS - start)) s ($build)"
cd "$build"
rm -rf test_results
status=0
ctest -j"$(nproc)" --output-on-failure "$@" >ctest.log 2>&1 || status=$?
grep -E "tests passed|Total Test time|^\s+[0-9]+ - " ctest.log || true
echo "quick_test: $((SECONDS - start)) s in all (ctest's log: $build/ctest.log)"
exit "$status"
