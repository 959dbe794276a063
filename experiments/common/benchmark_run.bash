# Sourced by the CPU scripts that run a Google Benchmark of the package (not run on its own).
#   usage: source "$root/experiments/common/benchmark_run.bash"
#          cpu_arguments "$root" "$@"        sets reps (5), min_time (0.1 s) and out ($root/doc)
#                                            from [--reps N] [--min-time S] [OUT_DIR]
#          run_benchmark CALLER TARGET ROOT JSON
# run_benchmark runs TARGET (the one given in BENCHMARK, or else the standalone build's, built
# first by scripts/build.sh into BUILD_DIR, default build/) with reps repetitions of at least
# min_time s each and writes its JSON to JSON; it exits with a message naming CALLER if there
# is no such benchmark.
# shellcheck disable=SC2034  # reps, min_time and out are for the caller
cpu_arguments() {
  local root=$1
  shift
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
}

run_benchmark() {
  local caller=$1 target=$2 root=$3 json=$4
  if [[ -z ${BENCHMARK:-} ]]; then
    local build_dir=${BUILD_DIR:-$root/build}
    BUILD_DIR=$build_dir "$root/scripts/build.sh" >/dev/null
    BENCHMARK=$build_dir/devel/lib/projection_collision_avoidance/$target
  fi
  test -x "$BENCHMARK" || {
    echo "$caller: no $target at $BENCHMARK (libbenchmark-dev installed?)" >&2
    exit 1
  }
  "$BENCHMARK" --benchmark_repetitions="$reps" --benchmark_min_time="$min_time" \
    --benchmark_format=json >"$json"
}
