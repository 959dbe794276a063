#!/usr/bin/env bash
# Takes the README's rviz screenshots of formation.launch, as scripts/make_screenshot.sh does for
# demo.launch: the launch with rviz under Xvfb (software OpenGL), captured with `import` once the
# plant's simulated time passes the given moment.
#   doc/rviz_formation_2d.png     figure_eight_2d, 4 followers, star, V, t ~ 21.5 s (disturbance)
#   doc/rviz_formation_3d.png     figure_eight_3d, 4 followers, chain, V, t ~ 22 s, pitched view
#                                 (rviz/formation_3d.rviz)
#   doc/rviz_formation_chain.png  paper_run2 (1-D), 5 followers, chain, line, 100 Hz, t ~ 22 s
# Usage: scripts/formation_screenshots.sh [2d] [3d] [chain]   (default: all three; ~1 min each)
#   OUT_DIR (default doc/), REAL_TIME_FACTOR (default 0.5), ROS_PORT (default 11412: its own
#   master, apart from other tests), SCREEN_DISPLAY (default :98). Needs a built workspace
#   (scripts/build.sh). The PNGs are reduced to 256 colours (ImageMagick `convert`).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${OUT_DIR:-$root/doc}
rtf=${REAL_TIME_FACTOR:-0.5}
port=${ROS_PORT:-11412}
shots=("$@")
(( ${#shots[@]} )) || shots=(2d 3d chain)
test -f "$root/build/devel/setup.bash" || "$root/scripts/build.sh" >/dev/null
set +u  # the workspace's setup scripts read unset variables
# shellcheck disable=SC1091
source "$root/build/devel/setup.bash"
set -u
export LIBGL_ALWAYS_SOFTWARE=1 DISPLAY=${SCREEN_DISPLAY:-:98}
export ROS_MASTER_URI=http://localhost:$port
mkdir -p "$out"
work=$(mktemp -d)
export ROS_LOG_DIR=$work/log
Xvfb "$DISPLAY" -screen 0 1280x720x24 >"$work/xvfb.log" 2>&1 &
xvfb=$!
launch=
stop_launch() {
  [[ -n $launch ]] || return 0
  kill -INT "$launch" 2>/dev/null || true
  wait "$launch" 2>/dev/null || true
  launch=
}
cleanup() { stop_launch; kill "$xvfb" 2>/dev/null || true; wait "$xvfb" 2>/dev/null || true;
            rm -rf "$work"; }
trap cleanup EXIT

# shoot SIMULATED_SECONDS OUTPUT.png RVIZ_CONFIG [roslaunch args...]
shoot() {
  local at=$1 output=$2 config=$3
  shift 3
  roslaunch --port "$port" projection_collision_avoidance formation.launch rviz:=true \
    rviz_config:="$config" sim_time:=true real_time_factor:="$rtf" "$@" >"$work/launch.log" 2>&1 &
  launch=$!
  # Wait (bounded) until simulated time passes $at.
  local deadline=$((SECONDS + 240))
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
  import -window root "$work/shot.png"
  stop_launch
  convert "$work/shot.png" -colors 256 "PNG8:$output"
  echo "wrote $output ($(stat -c %s "$output") bytes)"
}

for shot in "${shots[@]}"; do
  case $shot in
    2d) shoot 21.5 "$out/rviz_formation_2d.png" "$root/rviz/formation.rviz" \
          scenario:="$root/config/scenarios/figure_eight_2d.yaml" followers:=4 topology:=star shape:=v ;;
    3d) shoot 22 "$out/rviz_formation_3d.png" "$root/rviz/formation_3d.rviz" \
          scenario:="$root/config/scenarios/figure_eight_3d.yaml" followers:=4 topology:=chain shape:=v ;;
    chain) shoot 22 "$out/rviz_formation_chain.png" "$root/rviz/formation.rviz" \
          scenario:="$root/config/scenarios/paper_run2.yaml" followers:=5 topology:=chain \
          shape:=line control_rate:=100 ;;
    *) echo "formation_screenshots: unknown shot '$shot' (2d, 3d, chain)"; exit 1 ;;
  esac
done
