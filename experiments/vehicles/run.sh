#!/usr/bin/env bash
# A plot of a run of launch/vehicles.launch: the leader and 3 followers (differential-drive
# robots by default, on odometry, commands as cmd_vel, star, V) for 40 s of simulated time at
# real time, recorded (record:=true) and plotted by plot_vehicles.py from the bag:
#   doc/vehicles_run.png  (a) the x-y paths with heading arrows, and at the instant of the
#                         smallest separation the perimeter circles around the followers'
#                         controlled points; (b) each follower's ||xi|| against xi_max;
#                         (c) the distance of each follower's controlled point to its target's
#                         (from the odometry) against the perimeter; the push (20-23 s) shaded
# and prints, per follower, max ||xi||, xi_max, min distance of the controlled points,
# perimeter and ||xi|| at the end.
# Usage: experiments/vehicles/run.sh [--kind unicycle|velocity] [--input odometry|tf|position]
#          [--out PNG] [name:=value ...]
#   --kind   the followers' vehicles (default unicycle: the controlled point look_ahead = 0.4 m
#            ahead of the axle; velocity: holonomic, controlled at the origin)
#   --input  the followers' ~input (default odometry; position needs --kind velocity)
#   --out    the figure (default doc/vehicles_run.png)
#   name:=value  further arguments of vehicles.launch, passed through (e.g. look_ahead:=0.3)
#   ROS_PORT (default 11414: its own master, apart from other tests). ~50 s. Needs a built
#   workspace (scripts/build.sh).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
port=${ROS_PORT:-11414}
kind=unicycle
input=odometry
out=$root/doc/vehicles_run.png
look_ahead=0.4
extra=()
while (($#)); do
  case $1 in
    --kind) kind=$2; shift 2 ;;
    --input) input=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *:=*) [[ $1 == look_ahead:=* ]] && look_ahead=${1#look_ahead:=}
          extra+=("$1"); shift ;;
    *) echo "vehicles: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done
case $kind in unicycle|velocity) ;; *) echo "vehicles: --kind unicycle or velocity" >&2; exit 2 ;; esac
case $input in odometry|tf|position) ;; *)
  echo "vehicles: --input odometry, tf or position" >&2; exit 2 ;;
esac
if [[ $input == position && $kind != velocity ]]; then
  echo "vehicles: --input position needs --kind velocity" >&2; exit 2
fi
[[ $kind == unicycle ]] || look_ahead=0

test -f "$root/build/devel/setup.bash" || "$root/scripts/build.sh" >/dev/null
set +u  # the workspace's setup scripts read unset variables
# shellcheck disable=SC1091
source "$root/build/devel/setup.bash"
set -u
export ROS_MASTER_URI=http://localhost:$port
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export ROS_LOG_DIR=$work/log
mkdir -p "$(dirname "$out")"

start=$SECONDS
if ! timeout 300 roslaunch --port "$port" projection_collision_avoidance vehicles.launch \
    rviz:=false record:=true bag:="$work/vehicles.bag" duration:=40 real_time_factor:=1 \
    kind:="$kind" input:="$input" "${extra[@]}" >"$work/launch.log" 2>&1 \
    || [[ ! -f $work/vehicles.bag ]]; then
  tail -20 "$work/launch.log"; echo "vehicles: the run did not finish or left no bag" >&2; exit 1
fi
echo "vehicles: run of 40 s simulated took $((SECONDS - start)) s"
/usr/bin/python3 "$here/plot_vehicles.py" "$work/vehicles.bag" -o "$out" --look-ahead "$look_ahead" \
  --title "vehicles.launch kind:=$kind input:=$input${extra[*]:+ ${extra[*]}}, 40 s"
