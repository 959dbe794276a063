#!/usr/bin/env bash
# Sets up, builds and runs every test; exits non-zero if anything fails.
#  1. the package built in a fresh colcon workspace, as README's route does, and its tests built
#     there too; every test registered in CMakeLists.txt (gtests, rostests, the Python checks and
#     the cross-check with the SciPy reference) run by ctest, as many at a time as there are
#     cores (those that must run alone are RUN_SERIAL); then the multi-host cases of test/multihost/run_all.sh (network
#     namespaces, root only, two at a time); all read back with catkin_test_results;
#  2. beside all that, at the lowest CPU priority (nice 19: the installation, the colcon build
#     and a test that waits on the clock get the processor when they want it; this work takes
#     what is left), one after another: the sanitizer build, started once its packages are
#     installed (the rest of the installation keeps dpkg busy on one core); scripts/sanitize.sh's
#     tests, the core gtests under ASan + UBSan (clang, standalone CMake project) and a short
#     libFuzzer run ($SANITIZE_FUZZ_SECONDS, default 25 s); then, once the colcon build is done,
#     the other two routes, catkin_make and catkin build, each in a fresh workspace; every
#     workspace sourced and used as README says (scripts/check_workspace.sh);
#  3. the results of both, once both are done.
# The workspaces lie side by side in $TEST_BUILD_DIR (default: a new folder in $TMPDIR or /tmp),
# each built by scripts/workspace.sh through one ccache: what the first compiled, the others find.
# Each phase starts with a line "== phase NAME (at S s)", S the seconds since the first; those of
# step 2 read "== phase [beside] NAME (at S s)" and are printed when it ends
# (experiments/ci_time/ci_phases.py reads them).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
package=projection_collision_avoidance
jobs=$(nproc)
# ctest's tests at a time ($TEST_JOBS): the cores. One more is faster but not safe: a follower on
# positions then left its bound under the load (doc/testing.md).
test_jobs=${TEST_JOBS:-$jobs}

# phase NAME: "== phase [LANE] NAME (at S s)", S from the first phase (PCA_PHASE_EPOCH, shared
# with scripts/sanitize.sh), [LANE] in a lane run beside the main one (PCA_PHASE_LANE).
phase() {
  export PCA_PHASE_EPOCH=${PCA_PHASE_EPOCH:-$(date +%s)}
  echo "== phase ${PCA_PHASE_LANE:+[$PCA_PHASE_LANE] }$1 (at $(($(date +%s) - PCA_PHASE_EPOCH)) s)"
}

# The workspaces, outside the package (a workspace inside it, linked back to it from its src/,
# would let roslaunch and rospack find the package again at every level). Removed when every
# test passed, kept for a look otherwise.
if [[ -n ${TEST_BUILD_DIR:-} ]]; then
  tests_dir=$TEST_BUILD_DIR
  rm -rf "$tests_dir"
  mkdir -p "$tests_dir"
else
  tests_dir=$(mktemp -d "${TMPDIR:-/tmp}/$package-test.XXXXXX")
fi
echo "test: workspaces in $tests_dir"
passed_all=false
beside_pid=
# On the way out: stop the builds beside the tests if they still run; remove the workspaces
# when every test passed.
finish() {
  [[ -n $beside_pid ]] && kill -- "-$beside_pid" 2>/dev/null
  if [[ $passed_all == true ]]; then rm -rf "$tests_dir"; else echo "test: workspaces kept in $tests_dir"; fi
}
trap finish EXIT
trap 'exit 130' INT TERM

# check_workspace TOOL SPACE: README's route from there: source the workspace, then find, run and
# launch the package.
check_workspace() {
  local tool=$1 space=$2
  "$root/scripts/check_workspace.sh" "$space" >"$tests_dir/$tool/check.log" 2>&1 || {
    cat "$tests_dir/$tool/check.log"; echo "test: the $tool workspace does not run"; return 1; }
  echo "$tool: built; $(tail -1 "$tests_dir/$tool/check.log"); ccache: $(ccache_hits)"
  ccache --zero-stats >/dev/null
}

# "H of N compilations from the cache" since the last --zero-stats.
ccache_hits() {
  ccache --print-stats | awk -F'\t' '
    $1 == "direct_cache_hit" || $1 == "preprocessed_cache_hit" { hits += $2 }
    $1 == "cache_miss" { misses += $2 }
    END { printf "%d of %d compilations from the cache", hits, hits + misses }'
}

sanitize_dir=${SANITIZE_BUILD_DIR:-$root/build-sanitize}
fuzz_seconds=${SANITIZE_FUZZ_SECONDS:-25}
colcon_built=$tests_dir/colcon.built
# beside_the_tests: the builds that need no quiet machine, one after another.
beside_the_tests() {
  export PCA_PHASE_LANE=beside
  # A cache of its own (clang's objects are no use to the workspaces; and test.sh counts the
  # workspaces' hits).
  CCACHE_DIR=$(ccache -k cache_dir)-sanitize SANITIZE_BUILD_DIR=$sanitize_dir \
    "$root/scripts/sanitize.sh" --build-only
  # Its gtests and the fuzzing need no quiet machine either: nothing in them reads a clock.
  SANITIZE_BUILD_DIR=$sanitize_dir "$root/scripts/sanitize.sh" --no-build \
    --fuzz-seconds "$fuzz_seconds" || {
    echo "test: scripts/sanitize.sh failed (sanitizer tests or fuzzing)"
    return 1
  }
  # The other two routes find in the cache what the colcon build compiled.
  phase "waiting for the colcon build"
  while [[ ! -e $colcon_built ]]; do sleep 1; done
  phase "build: catkin_make workspace"
  "$root/scripts/workspace.sh" catkin_make "$tests_dir" >/dev/null
  check_workspace catkin_make "$tests_dir/catkin_make/devel"
  phase "build: catkin build workspace"
  "$root/scripts/workspace.sh" catkin_build "$tests_dir" >/dev/null
  check_workspace catkin_build "$tests_dir/catkin_build/devel"
  phase end
}

# What the sanitizer build needs first, then the rest beside it.
phase "setup: what the sanitizer build needs"
"$root/scripts/setup.sh" build-essential make cmake pkg-config ccache libeigen3-dev \
  libyaml-cpp-dev libyaml-dev googletest libgtest-dev clang libclang-rt-14-dev llvm python3
# A job of its own process group (set -m), so that finish() stops all of it; at nice 19.
beside_log=$tests_dir/beside.log
set -m
(renice -n 19 -p "$BASHPID" >/dev/null || true; beside_the_tests) >"$beside_log" 2>&1 &
beside_pid=$!
set +m
phase "setup: the rest (the sanitizer build beside it)"
"$root/scripts/setup.sh"

phase "build: colcon workspace and the tests"
ccache --zero-stats >/dev/null
build=$("$root/scripts/workspace.sh" colcon "$tests_dir" --tests)
check_workspace colcon "$tests_dir/colcon/install"
touch "$colcon_built"

phase "tests: gtests, rostests, Python checks (ctest -j$test_jobs)"
results=$build/test_results
rm -rf "$results"
(cd "$build" && ctest -j"$test_jobs" --output-on-failure >"$build/ctest.log" 2>&1) || true
grep -E "^ *[0-9]+/[0-9]+ Test +#" "$build/ctest.log" || true
grep -E "tests passed|Total Test time" "$build/ctest.log" || true

# Hosts of network namespaces (root only; reported as skipped with the reason otherwise).
phase "tests: multi-host"
MULTIHOST_JOBS=$jobs "$root/test/multihost/run_all.sh" "$build" "$results/$package" || true
results_ok=true
catkin_test_results --verbose "$results" || results_ok=false
# Count test cases from the JUnit files: "passed failed skipped".
read -r passed failed skipped < <(/usr/bin/python3 "$root/test/tools/count_test_results.py" "$results")
if [[ $results_ok != true || $failed -ne 0 || $passed -eq 0 ]]; then
  echo "$passed passed, $failed failed"
  echo "test: failing tests above (ctest's log: $build/ctest.log)"
  exit 1
fi

phase "waiting for the work beside the tests"
beside_status=0
wait "$beside_pid" || beside_status=$?
beside_pid=
cat "$beside_log"
if [[ $beside_status -ne 0 ]]; then
  echo "$passed passed, $failed failed, $skipped skipped; the work beside them FAILED"
  echo "test: a build or the sanitizer tests beside the tests failed (exit $beside_status; log above)"
  exit 1
fi

# The same count over the sanitizer build's gtest XML.
read -r san_passed san_failed _ < <(/usr/bin/python3 "$root/test/tools/count_test_results.py" "$sanitize_dir/test_results")
phase end
passed_all=true
echo "$passed passed, $failed failed, $skipped skipped" \
  "(and under ASan + UBSan: $san_passed passed, $san_failed failed; fuzzed $fuzz_seconds s)"
