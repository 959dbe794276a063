#!/usr/bin/env bash
# Latency of the follower pipeline in real time: experiments/probes/latency.launch, RUNS times per
# setting, each on its own master. latency_probe publishes measurements at 1 kHz for DURATION s
# to a bare roscpp relay (measurement_relay), a follower with ~trigger measurement and one with
# ~trigger timer (paper_run2.yaml at 1000 Hz), and measures publication -> relay output and
# publication -> command latencies and the followers' missed and late control periods.
# Prints a Markdown table of medians over the runs (relay p50/p99, measurement-triggered
# follower p50/p99 and its added latency over the relay of the same run, timer follower p50/p99,
# missed and late periods in %) and writes the raw per-run figures to CSV.
# Usage: experiments/ros_latency/run.sh [--runs N] [--duration S] [--keep-awake none|both|all]
#          [--realtime] [--follower-thread] [--only SETTING[,SETTING...]]
#          [--csv FILE] [--rate HZ] [--port PORT] [--work DIR]
#   --runs      launches per setting (default 3)
#   --duration  measured seconds per launch (default 60; plus ~10 s of start-up and warm-up)
#   --keep-awake  none: the machine as it is; all: with one nice-19 busy loop per core, which
#               keeps this VM's cores from halting when idle (a halted core wakes late, delaying
#               timers and deliveries); both (default): as is, then kept awake
#   --realtime  also a setting with every node (probe, relay, followers) under SCHED_FIFO
#               priority 50 (chrt; needs root or CAP_SYS_NICE) and the cores kept awake
#   --follower-thread  also a setting with both followers' control tick on their real-time thread
#               (~control_loop thread, ~control_priority 80, ~lock_memory true; needs root or
#               CAP_SYS_NICE and CAP_IPC_LOCK), the cores kept awake, probe and relay as in
#               keep-awake
#   --only      exactly these settings, in the order given, of as-is, keep-awake, realtime,
#               follower-thread (comma-separated; overrides --keep-awake, --realtime and
#               --follower-thread), e.g. --only follower-thread
#   --csv       raw per-run figures (default doc/ros_latency.csv)
#   --rate      Hz of the measurements and of control_rate (default 1000)
#   --port      ROS master port (default 11421)
#   --work      directory for the probe's JSON and the launch logs (default: a new temporary one)
# Builds what it needs first (BUILD_DIR, default build/). Timing-sensitive: the figures depend on
# the machine's load (the CSV records the load average and steal time of each run).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
build_dir=${BUILD_DIR:-$root/build}
runs=3
duration=60
keep_awake=both
csv=$root/doc/ros_latency.csv
rate=1000
port=11421
work=
realtime=()
follower_thread=()
only=()
while (($#)); do
  case $1 in
    --runs) runs=$2; shift 2 ;;
    --duration) duration=$2; shift 2 ;;
    --keep-awake) keep_awake=$2; shift 2 ;;
    --csv) csv=$2; shift 2 ;;
    --rate) rate=$2; shift 2 ;;
    --port) port=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --realtime) realtime=(--realtime); shift ;;
    --follower-thread) follower_thread=(--follower-thread); shift ;;
    --only) only=(--only "$2"); shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "ros_latency: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done
case $keep_awake in none|both|all) ;; *)
  echo "ros_latency: --keep-awake must be none, both or all" >&2; exit 2 ;;
esac
[[ -n $work ]] || work=$(mktemp -d /tmp/ros_latency.XXXXXX)

test -f "$build_dir/devel/setup.bash" || BUILD_DIR=$build_dir "$root/scripts/build.sh" >/dev/null
make -C "$build_dir" -j"$(nproc)" follower_node measurement_relay latency_probe >/dev/null
set +u  # the workspace's setup scripts read unset variables
# shellcheck disable=SC1091
source "$build_dir/devel/setup.bash"
set -u
export ROS_MASTER_URI=http://localhost:$port
echo "ros_latency: work directory (probe JSON, launch and ROS logs): $work" >&2
/usr/bin/python3 "$here/ros_latency.py" --runs "$runs" --duration "$duration" \
  --rate "$rate" --keep-awake "$keep_awake" --csv "$csv" --port "$port" --work "$work" \
  "${realtime[@]}" "${follower_thread[@]}" "${only[@]}"
