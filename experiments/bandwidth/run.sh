#!/usr/bin/env bash
# Bandwidth of one follower, per topic: launch/pair.launch (Run 2, simulated time at real speed)
# at each control rate, with every status (the default) and with ~status_rate 10 Hz; for each,
# bandwidth.py counts the serialised bytes of every topic the follower receives or sends for
# DURATION wall seconds and prints a Markdown table (doc/multi_host.md).
# Usage: experiments/bandwidth/run.sh [--duration S] [--rates "100 1000"] [--port PORT]
#   --duration  wall seconds counted per setting (default 20; plus ~10 s of start-up)
#   --rates     control rates (Hz) to measure (default "100 1000")
#   --port      ROS master port (default 11431)
set -eo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
duration=20
rates="100 1000"
port=11431
while [ $# -gt 0 ]; do
  case "$1" in
    --duration) duration=$2; shift 2 ;;
    --rates) rates=$2; shift 2 ;;
    --port) port=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
bash "$root/scripts/build.sh" >/dev/null
# shellcheck disable=SC1091
source "$root/build/devel/setup.bash"
export ROS_MASTER_URI=http://localhost:$port
scenario=$root/config/scenarios/paper_run2.yaml
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
first=1
for rate in $rates; do
  for status_rate in "" 10; do
    label="${rate} Hz, status $([ -n "$status_rate" ] && echo "${status_rate} Hz" || echo "every step")"
    roslaunch -p "$port" projection_collision_avoidance pair.launch scenario:="$scenario" \
      control_rate:="$rate" status_rate:="$status_rate" duration:=$((duration + 30)) \
      >"$work/launch.log" 2>&1 &
    launch=$!
    out=$(/usr/bin/python3 "$root/experiments/bandwidth/bandwidth.py" --duration "$duration" \
      --label "$label") || { tail -20 "$work/launch.log"; kill "$launch"; exit 1; }
    if [ $first = 1 ]; then echo "$out"; first=0; else echo "$out" | grep -v -e "^| setting" -e "^|---"; fi
    kill -INT "$launch" 2>/dev/null || true
    wait "$launch" 2>/dev/null || true
  done
done
