#!/usr/bin/env bash
# Takes the rviz screenshots of doc/nodes.md: demo.launch (the paper's Run 2) under Xvfb, captured at
# a simulated time. Without arguments: t ~ 21.5 s, while the leader is pushed back, into
# doc/rviz_run2.png. Further arguments go to roslaunch, e.g. for the fallback:
#   experiments/demo_screenshot/run.sh 27 doc/rviz_fallback.png acceleration_limit:=6 \
#     measurement_outage_start:=25 measurement_outage_duration:=3
# Usage: experiments/demo_screenshot/run.sh [simulated_seconds [output.png [roslaunch args...]]]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
at=${1:-21.5}
output=${2:-$root/doc/rviz_run2.png}
shift $(( $# < 2 ? $# : 2 ))
"$root/scripts/build.sh" >/dev/null
set +u  # the workspace's setup scripts read unset variables
# shellcheck disable=SC1091
source "$root/build/devel/setup.bash"
set -u
export LIBGL_ALWAYS_SOFTWARE=1 DISPLAY=:97
work=$(mktemp -d)
Xvfb "$DISPLAY" -screen 0 1280x720x24 >"$work/xvfb.log" 2>&1 &
xvfb=$!
roslaunch projection_collision_avoidance demo.launch real_time_factor:=0.5 \
  control_rate:=100 "$@" >"$work/launch.log" 2>&1 &
launch=$!
cleanup() { kill "$launch" 2>/dev/null || true; wait "$launch" 2>/dev/null || true;
            kill "$xvfb" 2>/dev/null || true; rm -rf "$work"; }
trap cleanup EXIT
# Wait (bounded) until simulated time passes $at.
deadline=$((SECONDS + 180))
until /usr/bin/python3 - "$at" <<'PY' 2>/dev/null
import sys, rospy
from rosgraph_msgs.msg import Clock
rospy.init_node("screenshot_clock", anonymous=True, disable_signals=True)
t = rospy.wait_for_message("/clock", Clock, timeout=5).clock.to_sec()
sys.exit(0 if t >= float(sys.argv[1]) else 1)
PY
do
  (( SECONDS < deadline )) || { tail -20 "$work/launch.log"; echo "no simulated time"; exit 1; }
  sleep 0.5
done
import -window root "$output"
echo "wrote $output"
