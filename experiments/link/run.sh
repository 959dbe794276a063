#!/usr/bin/env bash
# TCPROS against UDPROS for the relative measurement across two hosts (network namespaces, root).
# The world host runs the master, the plant and the leader (pair.launch, wall time, 100 Hz); the
# follower host runs the follower with ~transport tcp or udp and a link_probe subscribed the same
# way. A second link_probe on the world host (TCP over loopback) sees every measurement the plant
# sent. Per transport, four conditions: none; the plant's measurement dropout (0.2); its latency
# (0.05 s); and a flood of other traffic on the same link (link_flood: --flood-rate Hz of
# --flood-bytes B messages from the world host to a subscriber on the follower host).
# Prints a Markdown table (latency p50/p99/max of receipt - stamp at the follower host, measurements
# sent, lost on the link, refused by the follower) and writes it as CSV (--csv).
# Usage: experiments/link/run.sh [--duration S] [--flood-rate HZ] [--flood-bytes B] [--csv FILE]
#          [--build DIR] [--log DIR]   (default 60 s, 10000 Hz, 1000 B, doc/link_transport.csv,
#          ./build; --log keeps the hosts' logs and the probes' files there)
# Takes about (duration + 15 s) x 8.
set -eo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
duration=60
flood_rate=10000
flood_bytes=1000
csv=$root/doc/link_transport.csv
build=$root/build
keep_log=""
while [[ $# -gt 0 ]]; do
  case $1 in
    --duration) duration=$2; shift 2 ;;
    --flood-rate) flood_rate=$2; shift 2 ;;
    --flood-bytes) flood_bytes=$2; shift 2 ;;
    --csv) csv=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --log) keep_log=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
BUILD_DIR=$build "$root/scripts/build.sh" link_probe link_flood >/dev/null
# shellcheck disable=SC1091
source "$build/devel/setup.bash"
log=${keep_log:-$(mktemp -d)}
mkdir -p "$log"
# shellcheck source=../../test/multihost/netns.sh
source "$root/test/multihost/netns.sh"
make_hosts 1
bin=$build/devel/lib/projection_collision_avoidance
scenario=$(rospack find projection_collision_avoidance)/config/scenarios/paper_run2.yaml
span=$((duration + 11))
results=$log/results
mkdir -p "$results"

run_setting() {  # run_setting TRANSPORT CONDITION
  local transport=$1 condition=$2 dir=$results/$1_$2 faults=() floods=()
  mkdir -p "$dir"
  case $condition in
    dropout) faults=(measurement_dropout:=0.2) ;;
    latency) faults=(measurement_latency:=0.05) ;;
  esac
  # Both probes count the measurements stamped in the same window, from 8 s on (after the
  # launches below have started).
  local start
  start=$(/usr/bin/python3 -c 'import time; print(f"{time.time() + 8:.3f}")')
  on_host 1 roslaunch projection_collision_avoidance pair.launch scenario:="$scenario" \
    world:=false sim_time:=false control_rate:=100 transport:="$transport" >"$dir/follower.log" 2>&1 &
  local follower=$!
  on_host 1 "$bin/link_probe" __name:=link_probe_follower_host measurement:=/follower/relative_measurement _transport:="$transport" \
    _start:="$start" _duration:="$duration" _output:="$dir/follower_host.txt" >"$dir/probe.log" 2>&1 &
  local probe=$!
  if [[ $condition == flood ]]; then
    on_host 1 "$bin/link_flood" __name:=flood_subscriber _mode:=subscribe _duration:=$span >"$dir/flood_sub.log" 2>&1 &
    floods+=($!)
    sleep 1
    on_host 0 "$bin/link_flood" __name:=flood_publisher _mode:=publish _rate:="$flood_rate" _bytes:="$flood_bytes" \
      _duration:=$span >"$dir/flood_pub.log" 2>&1 &
    floods+=($!)
  fi
  sleep 2
  on_host 0 roslaunch projection_collision_avoidance pair.launch scenario:="$scenario" \
    follower:=false sim_time:=false control_rate:=100 "${faults[@]}" >"$dir/world.log" 2>&1 &
  local world=$!
  on_host 0 "$bin/link_probe" __name:=link_probe_world_host measurement:=/follower/relative_measurement _transport:=tcp \
    _start:="$start" _duration:="$duration" _output:="$dir/world_host.txt" >"$dir/world_probe.log" 2>&1
  wait "$probe"
  on_host 1 rostopic echo -n 1 /follower/status/rejected_measurements 2>/dev/null |
    head -1 >"$dir/rejected.txt" || true
  # Each background job is a subshell around ip netns exec: signal the launch it started.
  pkill -INT -P "$world" 2>/dev/null || true
  pkill -INT -P "$follower" 2>/dev/null || true
  wait "$world" "$follower" "${floods[@]}" 2>/dev/null || true
  echo "$transport $condition done" >&2
}

for transport in tcp udp; do
  for condition in none dropout latency flood; do
    run_setting "$transport" "$condition"
  done
done
/usr/bin/python3 "$root/experiments/link/link_table.py" "$results" --csv "$csv" \
  --flood "$flood_rate Hz x $flood_bytes B"
