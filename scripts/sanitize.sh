#!/usr/bin/env bash
# Builds the ROS-free core with AddressSanitizer + UndefinedBehaviorSanitizer (clang, standalone
# CMake project test/sanitize/, no catkin), runs the core gtests under them, then fuzzes the
# controller with libFuzzer for N seconds from a copy of the seed corpus. Exits non-zero on any
# failure (a failing test, a sanitizer report, a crash or invariant violation found by the fuzzer).
# Usage: scripts/sanitize.sh [--fuzz-seconds N] [--build-only | --no-build]
#   --fuzz-seconds N  fuzz for N seconds (default 20; 0 skips the fuzz run)
#   --build-only      only build; --no-build: only test what an earlier --build-only built
#                     (scripts/test.sh builds beside its rostests, then tests on a quiet machine)
# Environment: SANITIZE_BUILD_DIR (default build-sanitize/), CXX (default clang++), JOBS (2).
# A long fuzz run: scripts/sanitize.sh --fuzz-seconds 3600. A crash leaves its input in
# $SANITIZE_BUILD_DIR/fuzz/crash-*; replay it with
#   $SANITIZE_BUILD_DIR/fuzz_follower_controller CRASH_FILE   (FUZZ_FOLLOWER_VERBOSE=1 to see the
# decoded parameters).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${SANITIZE_BUILD_DIR:-$root/build-sanitize}
fuzz_seconds=20
stages=all
while [[ $# -gt 0 ]]; do
  case $1 in
    --fuzz-seconds) fuzz_seconds=${2:?--fuzz-seconds needs a value}; shift 2 ;;
    --fuzz-seconds=*) fuzz_seconds=${1#*=}; shift ;;
    --build-only) stages=build; shift ;;
    --no-build) stages=tests; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "sanitize: unknown argument $1" >&2; exit 2 ;;
  esac
done
[[ $fuzz_seconds =~ ^[0-9]+$ ]] || { echo "sanitize: --fuzz-seconds needs an integer" >&2; exit 2; }

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:detect_stack_use_after_return=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
if symbolizer=$(command -v llvm-symbolizer); then
  export ASAN_SYMBOLIZER_PATH=$symbolizer
fi

# phase NAME: "== phase [LANE] NAME (at S s)", S from the first phase of this run
# (PCA_PHASE_EPOCH, shared with scripts/test.sh), [LANE] when PCA_PHASE_LANE names the lane of a
# run beside another (scripts/test.sh).
phase() {
  export PCA_PHASE_EPOCH=${PCA_PHASE_EPOCH:-$(date +%s)}
  echo "== phase ${PCA_PHASE_LANE:+[$PCA_PHASE_LANE] }$1 (at $(($(date +%s) - PCA_PHASE_EPOCH)) s)"
}

# The core, its gtests and the fuzzer, built with the sanitizers.
build_sanitized() {
  phase "sanitizers: build"
  echo "ASan + UBSan, clang, in $build_dir"
  local start=$SECONDS launcher=()
  # Through ccache when there is one (a rebuild of the same sources comes out of the cache).
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  cmake -S "$root/test/sanitize" -B "$build_dir" -DCMAKE_CXX_COMPILER="${CXX:-clang++}" \
    "${launcher[@]}" >/dev/null
  make -C "$build_dir" -j"${JOBS:-2}" >"$build_dir/build.log" 2>&1 || {
    tail -40 "$build_dir/build.log"
    echo "sanitize: build failed (log: $build_dir/build.log)"
    exit 1
  }
  echo "built in $((SECONDS - start)) s"
}

[[ $stages == tests ]] || build_sanitized
[[ $stages == build ]] && exit 0
[[ -x $build_dir/fuzz_follower_controller ]] || {
  echo "sanitize: nothing built in $build_dir (run without --no-build)"; exit 1; }

phase "sanitizers: gtests"
rm -rf "$build_dir/test_results"
# Every core gtest but the chain of 100 at 1 kHz: 231 s of 727 under ASan, it runs the code of
# the chain at 100 Hz (run here) ten times as long; the plain build runs it (test_string_stability).
(cd "$build_dir" && ctest -j"${JOBS:-2}" --output-on-failure \
  -E '^StringStability\.ChosenConfigurationHoldsAChainOf100At1kHz$') || {
  echo "sanitize: core gtests failed"
  exit 1
}
# Test cases from the gtest XML files (test_results/*.xml): "passed failed".
read -r passed failed _ < <(/usr/bin/python3 "$root/test/tools/count_test_results.py" "$build_dir/test_results")
echo "sanitizer gtests: $passed passed, $failed failed"
if [[ $failed -ne 0 || $passed -eq 0 ]]; then
  echo "sanitize: core gtests failed"
  exit 1
fi

if [[ $fuzz_seconds -gt 0 ]]; then
  phase "sanitizers: fuzzing"
  echo "fuzz_follower_controller for $fuzz_seconds s"
  fuzz_dir=$build_dir/fuzz
  rm -rf "$fuzz_dir"
  mkdir -p "$fuzz_dir/corpus"
  cp "$root"/test/fuzz/corpus/* "$fuzz_dir/corpus/"  # a copy: libFuzzer adds to it
  (cd "$fuzz_dir" && "$build_dir/fuzz_follower_controller" -max_total_time="$fuzz_seconds" \
    -print_final_stats=1 -timeout=10 corpus >"$fuzz_dir/fuzz.log" 2>&1) || {
    grep -v -E '^#[0-9]+' "$fuzz_dir/fuzz.log" | tail -60
    echo "sanitize: the fuzzer found a failure (log: $fuzz_dir/fuzz.log; input: $fuzz_dir/crash-*)"
    exit 1
  }
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$fuzz_dir/fuzz.log")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$fuzz_dir/fuzz.log")
  echo "fuzz: ${runs:-?} inputs in $fuzz_seconds s (${rate:-?}/s), no failure"
fi
echo "sanitize: passed"
