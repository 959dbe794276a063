#!/usr/bin/env bash
# The main job: sets up, builds, and runs the ROS demo of the paper's scenario (leader, follower
# and simulated plant on simulated time, the follower at 100 Hz).
#  - With a display ($DISPLAY set): Run 2 (CF tracker on) in real time with rviz.
#  - Without one: Run 1 and Run 2 headless at 5x real time.
# Either way each run is recorded; its summary line and plot are left in out/ (or $OUT_DIR):
# runN.bag, runN.png, and the cf_sim figures of the same scenario for comparison.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${OUT_DIR:-$root/out}

"$root/scripts/setup.sh"
"$root/scripts/build.sh"
set +u  # the workspace's setup scripts read unset variables
# shellcheck disable=SC1091
source "$root/build/devel/setup.bash"
set -u
cf_sim=$root/build/devel/lib/projection_collision_avoidance/cf_sim
mkdir -p "$out"

if [[ -n "${DISPLAY:-}" ]]; then
  runs=(2)
  launch_args=(rviz:=true real_time_factor:=1 control_rate:=100)
else
  runs=(1 2)
  launch_args=(rviz:=false real_time_factor:=5 control_rate:=100)
  echo "demo: no display, running headless"
fi

for run in "${runs[@]}"; do
  bag=$out/run$run.bag
  rm -f "$bag"
  echo "== Run $run through ROS ($( [[ $run == 1 ]] && echo "tracker off" || echo "tracker on" ))"
  # The launch starts its own master and ends when the plant stops after 60 simulated seconds.
  roslaunch projection_collision_avoidance "paper_run$run.launch" "${launch_args[@]}" \
    record:=true bag:="$bag" >"$out/run$run.log" 2>&1 || true
  test -s "$bag" || { tail -30 "$out/run$run.log"; echo "demo: no bag from run $run"; exit 1; }
  echo -n "ROS:    "
  /usr/bin/python3 "$root/scripts/bag_summary.py" "$bag"
  echo -n "cf_sim: "
  "$cf_sim" "$root/config/scenarios/paper_run$run.yaml" --set controller.control_rate=100
  /usr/bin/python3 "$root/scripts/plot_run.py" "$bag" --title "Run $run through ROS" \
    -o "$out/run$run.png"
done
echo "demo: results in $out (bags, plots, logs)"
