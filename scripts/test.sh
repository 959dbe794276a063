#!/usr/bin/env bash
# Sets up, builds and runs every test; exits non-zero if anything fails.
#  1. standalone build (cmake + make), all tests (gtest + cross-check with the SciPy reference),
#     read back with catkin_test_results;
#  2. the everyday ROS routes: the package in a fresh workspace built with catkin_make and with
#     catkin build (catkin-tools);
#  3. scripts/sanitize.sh: the core gtests under ASan + UBSan (clang, standalone CMake project) and
#     a short libFuzzer run ($SANITIZE_FUZZ_SECONDS, default 25 s).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

"$root/scripts/setup.sh" --workspace-tools

echo "== standalone build and tests"
build_dir=${BUILD_DIR:-$root/build}
BUILD_DIR=$build_dir "$root/scripts/build.sh" tests
rm -rf "$build_dir/test_results"
make -C "$build_dir" run_tests >"$build_dir/run_tests.log" 2>&1 || {
  tail -50 "$build_dir/run_tests.log"
  echo "test: make run_tests failed (log: $build_dir/run_tests.log)"
  exit 1
}
results_ok=true
catkin_test_results --verbose "$build_dir/test_results" || results_ok=false
# Count test cases from the JUnit files: "passed failed skipped".
read -r passed failed skipped < <(/usr/bin/python3 "$root/scripts/count_test_results.py" "$build_dir/test_results")
if [[ $results_ok != true || $failed -ne 0 || $passed -eq 0 ]]; then
  echo "$passed passed, $failed failed"
  echo "test: failing tests above"
  exit 1
fi

echo "== catkin workspace builds"
workspaces=$(mktemp -d)
trap 'rm -rf "$workspaces"' EXIT
for tool in catkin_make catkin_build; do
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
  esac || { tail -40 "$ws/build.log"; echo "test: $tool failed"; exit 1; }
  test -x "$ws/devel/lib/projection_collision_avoidance/cf_sim" || {
    echo "test: $tool built no cf_sim"; exit 1; }
  echo "$tool: built"
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
read -r san_passed san_failed san_skipped < <(/usr/bin/python3 "$root/scripts/count_test_results.py" "$sanitize_dir/test_results")
echo "$passed passed, $failed failed, $skipped skipped" \
  "(and under ASan + UBSan: $san_passed passed, $san_failed failed; fuzzed $fuzz_seconds s)"
