#!/usr/bin/env bash
# Takes the README's rviz screenshot: the paper's Run 2 under Xvfb, captured while the leader is
# pushed back (simulated t ~ 21.5 s). Writes doc/rviz_run2.png.
# Usage: scripts/make_screenshot.sh [simulated_seconds]   (builds first)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
at=${1:-21.5}
"$root/scripts/build.sh" >/dev/null
set +u  # the workspace's setup scripts read unset variables
# shellcheck disable=SC1091
source "$root/build/devel/setup.bash"
set -u
export LIBGL_ALWAYS_SOFTWARE=1 DISPLAY=:97
work=$(mktemp -d)
Xvfb "$DISPLAY" -screen 0 1280x720x24 >"$work/xvfb.log" 2>&1 &
xvfb=$!
roslaunch projection_collision_avoidance paper_run2.launch real_time_factor:=0.5 \
  control_rate:=100 >"$work/launch.log" 2>&1 &
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
import -window root "$root/doc/rviz_run2.png"
echo "wrote doc/rviz_run2.png"
