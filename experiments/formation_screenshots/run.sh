#!/usr/bin/env bash
# Takes the rviz screenshots of doc/formations.md (formation.launch), as
# experiments/demo_screenshot/run.sh does for demo.launch: rviz under Xvfb (software OpenGL) on the formation, its window captured with
# `import` once the plant's simulated time passes the given moment. The master and rviz start
# first and formation.launch (rviz:=false) only once rviz's window is up; rviz runs a copy of the
# configuration without its Displays panel, for a wider view.
#   doc/rviz_formation_2d.png     figure_eight_2d, 4 followers, star, V, t = 21.5 s (during the
#                                 disturbance), rviz/formation.rviz
#   doc/rviz_formation_3d.png     figure_eight_3d, 4 followers, chain, V, t = 22 s, a low camera
#                                 over the ground grid (rviz/formation_3d.rviz)
#   doc/rviz_formation_chain.png  paper_run2 (1-D), 5 followers, chain, line, 100 Hz, t = 22 s,
#                                 side view in a 1280x420 window (rviz/formation_line.rviz)
#   doc/rviz_vehicles.png         vehicles.launch: 3 differential-drive followers on odometry and
#                                 cmd_vel, star, V, t = 21.5 s (during the push), formation.rviz
#   doc/rviz_formation_turning.png  figure_eight_2d, 4 followers, star, V, slots:=turning,
#                                 t = 13 s (the leader turning round a loop), formation.rviz
#   doc/rviz_formation_path.png   figure_eight_2d, 4 followers, chain, line, slots:=path,
#                                 t = 13 s (the convoy on the leader's loop), seen from above
#                                 (rviz/formation_path.rviz)
#   doc/rviz_neighbours.png       crowd_v4_gust, 4 followers, star, V, formation.neighbours,
#                                 t = 21.5 s (follower 2 pushed toward follower 1), each sensed
#                                 agent's perimeter coloured by what its constraint does
#                                 (formation.rviz)
# Usage: experiments/formation_screenshots/run.sh [2d] [3d] [chain] [vehicles] [turning] [path]
#   [neighbours] (default: all seven; ~1 min each)
#   OUT_DIR (default doc/), REAL_TIME_FACTOR (default 0.5), ROS_PORT (default 11412: its own
#   master, apart from other tests), SCREEN_DISPLAY (default :98), BUILD_DIR (default build/,
#   built by scripts/build.sh when missing). The PNGs are reduced to 256 colours (ImageMagick `convert`).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
out=${OUT_DIR:-$root/doc}
rtf=${REAL_TIME_FACTOR:-0.5}
port=${ROS_PORT:-11412}
shots=("$@")
(( ${#shots[@]} )) || shots=(2d 3d chain vehicles turning path neighbours)
launch=formation.launch  # the launch file of the current shot
build=${BUILD_DIR:-$root/build}
test -f "$build/devel/setup.bash" || BUILD_DIR=$build "$root/scripts/build.sh" >/dev/null
set +u  # the workspace's setup scripts read unset variables
# shellcheck disable=SC1091
source "$build/devel/setup.bash"
set -u
export LIBGL_ALWAYS_SOFTWARE=1 DISPLAY=${SCREEN_DISPLAY:-:98}
export ROS_MASTER_URI=http://localhost:$port
mkdir -p "$out"
work=$(mktemp -d)
export ROS_LOG_DIR=$work/log
Xvfb "$DISPLAY" -screen 0 1280x720x24 >"$work/xvfb.log" 2>&1 &
xvfb=$!
pids=()  # roscore, rviz, roslaunch of the current shot
stop_shot() {
  local i
  for (( i = ${#pids[@]} - 1; i >= 0; i-- )); do  # roslaunch first, roscore last
    kill -INT "${pids[i]}" 2>/dev/null || true
    wait "${pids[i]}" 2>/dev/null || true
  done
  pids=()
}
cleanup() { stop_shot; kill "$xvfb" 2>/dev/null || true; wait "$xvfb" 2>/dev/null || true;
            rm -rf "$work"; }
trap cleanup EXIT

# shoot SIMULATED_SECONDS OUTPUT.png RVIZ_CONFIG [roslaunch args...]
# Starts the master and rviz first and the formation (rviz:=false) only once rviz's window is up,
# so that a slow rviz start cannot miss the moment.
shoot() {
  local at=$1 output=$2 deadline
  # The configuration without its panels (the Displays list): a wider 3-D view.
  awk '/^Panels:/ { print "Panels: []"; skip = 1; next }
       skip && /^ / { next }
       { skip = 0; print }' "$3" >"$work/view.rviz"
  shift 3
  roscore -p "$port" >"$work/roscore.log" 2>&1 &
  pids+=($!)
  deadline=$((SECONDS + 60))
  until rosparam set /use_sim_time true 2>/dev/null; do
    (( SECONDS < deadline )) || { cat "$work/roscore.log"; echo "no master"; exit 1; }
    sleep 0.5
  done
  rviz -d "$work/view.rviz" >"$work/rviz.log" 2>&1 &
  pids+=($!)
  until xwininfo -root -tree | grep -q 'view.rviz - RViz'; do
    (( SECONDS < deadline )) || { cat "$work/rviz.log"; echo "no rviz window"; exit 1; }
    sleep 0.5
  done
  sleep 3
  roslaunch --port "$port" projection_collision_avoidance "$launch" rviz:=false \
    sim_time:=true real_time_factor:="$rtf" "$@" >"$work/launch.log" 2>&1 &
  pids+=($!)
  # Wait (bounded) until simulated time passes $at: one subscriber, up before the plant is.
  if ! /usr/bin/python3 - "$at" 240 >/dev/null 2>&1 <<'PY'
import sys, threading, rospy
from rosgraph_msgs.msg import Clock
at, timeout = float(sys.argv[1]), float(sys.argv[2])
passed = threading.Event()
rospy.init_node("screenshot_clock", anonymous=True, disable_signals=True)
rospy.Subscriber("/clock", Clock, lambda m: m.clock.to_sec() >= at and passed.set(), queue_size=1)
sys.exit(0 if passed.wait(timeout) else 1)
PY
  then
    tail -20 "$work/launch.log"; echo "no simulated time $at s"; exit 1
  fi
  # rviz's window alone (its size is the configuration's Window Geometry).
  import -window "$(xwininfo -name 'view.rviz - RViz' | awk '/Window id:/ { print $4 }')" \
    "$work/shot.png"
  stop_shot
  convert "$work/shot.png" -colors 256 "PNG8:$output"
  echo "wrote $output ($(stat -c %s "$output") bytes)"
}

for shot in "${shots[@]}"; do
  case $shot in
    2d) shoot 21.5 "$out/rviz_formation_2d.png" "$root/rviz/formation.rviz" \
          scenario:="$root/config/scenarios/figure_eight_2d.yaml" followers:=4 topology:=star shape:=v ;;
    3d) shoot 22 "$out/rviz_formation_3d.png" "$root/rviz/formation_3d.rviz" \
          scenario:="$root/config/scenarios/figure_eight_3d.yaml" followers:=4 topology:=chain shape:=v ;;
    chain) shoot 22 "$out/rviz_formation_chain.png" "$root/rviz/formation_line.rviz" \
          scenario:="$root/config/scenarios/paper_run2.yaml" followers:=5 topology:=chain \
          shape:=line control_rate:=100 ;;
    turning) shoot 13 "$out/rviz_formation_turning.png" "$root/rviz/formation.rviz" \
          scenario:="$root/config/scenarios/figure_eight_2d.yaml" followers:=4 topology:=star \
          shape:=v slots:=turning ;;
    path) shoot 13 "$out/rviz_formation_path.png" "$root/rviz/formation_path.rviz" \
          scenario:="$root/config/scenarios/figure_eight_2d.yaml" followers:=4 topology:=chain \
          shape:=line slots:=path ;;
    neighbours) shoot 21.5 "$out/rviz_neighbours.png" "$root/rviz/formation.rviz" \
          scenario:="$root/config/scenarios/crowd_v4_gust.yaml" followers:=4 topology:=star \
          shape:=v neighbours:="{braking_acceleration: 1, neighbour_acceleration: 2, rate: 1}" ;;
    vehicles) launch=vehicles.launch
          shoot 21.5 "$out/rviz_vehicles.png" "$root/rviz/formation.rviz" followers:=3 kind:=unicycle
          launch=formation.launch ;;
    *) echo "formation_screenshots: unknown shot '$shot' (2d, 3d, chain, vehicles, turning, path, neighbours)"; exit 1 ;;
  esac
done
