#!/usr/bin/env bash
# Sets up, builds and runs every test; exits non-zero if anything fails.
#  1. standalone build (cmake + make), all tests (gtest + cross-check with the SciPy reference),
#     the multi-host cases of test/multihost/run_all.sh (network namespaces, root only), all read
#     back with catkin_test_results;
#  2. the everyday ROS routes: the package in a fresh workspace built with catkin_make, catkin build
#     (catkin-tools) and colcon build, each sourced and used as README says
#     (scripts/check_workspace.sh);
#  3. scripts/sanitize.sh: the core gtests under ASan + UBSan (clang, standalone CMake project) and
#     a short libFuzzer run ($SANITIZE_FUZZ_SECONDS, default 25 s).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

"$root/scripts/setup.sh"

echo "== standalone build and tests"
build_dir=${BUILD_DIR:-$root/build}
BUILD_DIR=$build_dir "$root/scripts/build.sh" tests
rm -rf "$build_dir/test_results"
make -C "$build_dir" run_tests >"$build_dir/run_tests.log" 2>&1 || {
  tail -50 "$build_dir/run_tests.log"
  echo "test: make run_tests failed (log: $build_dir/run_tests.log)"
  exit 1
}
# Hosts of network namespaces (root only; reported as skipped with the reason otherwise).
echo "== multi-host tests"
"$root/test/multihost/run_all.sh" "$build_dir" "$build_dir/test_results/projection_collision_avoidance" || true
results_ok=true
catkin_test_results --verbose "$build_dir/test_results" || results_ok=false
# Count test cases from the JUnit files: "passed failed skipped".
read -r passed failed skipped < <(/usr/bin/python3 "$root/test/tools/count_test_results.py" "$build_dir/test_results")
if [[ $results_ok != true || $failed -ne 0 || $passed -eq 0 ]]; then
  echo "$passed passed, $failed failed"
  echo "test: failing tests above"
  exit 1
fi

echo "== workspace builds: catkin_make, catkin build, colcon build"
workspaces=$(mktemp -d)
trap 'rm -rf "$workspaces"' EXIT
for tool in catkin_make catkin_build colcon; do
  ws=$workspaces/$tool
  mkdir -p "$ws/src"
  ln -s "$root" "$ws/src/projection_collision_avoidance"
  case $tool in
    catkin_make)
      (cd "$ws" && catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 >"$ws/build.log" 2>&1) ;;
    catkin_build)
      (cd "$ws" && catkin init >/dev/null &&
        catkin config --cmake-args -DPYTHON_EXECUTABLE=/usr/bin/python3 >/dev/null &&
        catkin build --no-status >"$ws/build.log" 2>&1) ;;
    colcon)
      (cd "$ws" && colcon build --cmake-args -DPYTHON_EXECUTABLE=/usr/bin/python3 \
        >"$ws/build.log" 2>&1) ;;
  esac || { tail -40 "$ws/build.log"; echo "test: $tool failed"; exit 1; }
  # README's route from there: source the workspace, then find, run and launch the package.
  space=$ws/devel
  [[ $tool == colcon ]] && space=$ws/install
  "$root/scripts/check_workspace.sh" "$space" >"$ws/check.log" 2>&1 || {
    cat "$ws/check.log"; echo "test: the $tool workspace does not run"; exit 1; }
  echo "$tool: built; $(tail -1 "$ws/check.log")"
done

echo "== sanitizers and fuzzing"
sanitize_dir=${SANITIZE_BUILD_DIR:-$root/build-sanitize}
fuzz_seconds=${SANITIZE_FUZZ_SECONDS:-25}
SANITIZE_BUILD_DIR=$sanitize_dir "$root/scripts/sanitize.sh" --fuzz-seconds "$fuzz_seconds" || {
  echo "$passed passed, $failed failed, $skipped skipped; sanitizer build or fuzzing FAILED"
  echo "test: scripts/sanitize.sh failed"
  exit 1
}
# The same count over the sanitizer build's gtest XML.
read -r san_passed san_failed san_skipped < <(/usr/bin/python3 "$root/test/tools/count_test_results.py" "$sanitize_dir/test_results")
echo "$passed passed, $failed failed, $skipped skipped" \
  "(and under ASan + UBSan: $san_passed passed, $san_failed failed; fuzzed $fuzz_seconds s)"
