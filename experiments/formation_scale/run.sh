#!/usr/bin/env bash
# How many followers formation.launch holds at 100 Hz in real time, as processes and as nodelets:
# for each mode and N, launches formation.launch (paper_run2.yaml, control_rate:=100, star, line,
# sim_time:=false, rviz:=false) on its own master, waits until every follower publishes its
# status, records the statuses (rosbag record) and the nodes' CPU time over a window of WINDOW
# wall seconds, stops the launch and checks that nothing of it remains (formation_scale.py,
# beside this script).
# Writes OUT_DIR/formation_scale.md (table) and OUT_DIR/formation_scale.png (CPU and rate vs N).
# Usage: experiments/formation_scale/run.sh [N ...]   (default 1 2 4 8 16 32 64; a mode stops
#                                     at the first N that fails badly twice)  ~17 min
#   KEEP_AWAKE: both (default) runs every size twice, first on the machine as it is, then with a
#   nice-19 busy loop per core that keeps the VM's cores from halting when idle (on a VM, waking
#   a halted core can delay a timer by tens of ms); no or yes for one of the two passes.
#   WINDOW (default 20 s), MODES (default "processes nodelets"), RATE (default 100 Hz),
#   ROS_PORT (default 11411), OUT_DIR (default doc/), RESULTS (raw results, JSON lines; default
#   a temporary file). Needs a built workspace (scripts/build.sh).
#   Timing-sensitive: run it on an otherwise idle machine (the table reports the load).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${OUT_DIR:-$root/doc}
window=${WINDOW:-20}
keep_awake=${KEEP_AWAKE:-both}
rate=${RATE:-100}
port=${ROS_PORT:-11411}
read -r -a modes <<<"${MODES:-processes nodelets}"
sizes=("$@")
(( ${#sizes[@]} )) || sizes=(1 2 4 8 16 32 64)
test -f "$root/build/devel/setup.bash" || "$root/scripts/build.sh" >/dev/null
set +u  # the workspace's setup scripts read unset variables
# shellcheck disable=SC1091
source "$root/build/devel/setup.bash"
set -u
export ROS_MASTER_URI=http://localhost:$port
mkdir -p "$out"
results=${RESULTS:-$(mktemp --suffix=.jsonl)}
: >"$results"
command="experiments/formation_scale/run.sh ${sizes[*]}"
[[ $window == 20 ]] || command="WINDOW=$window $command"
[[ ${MODES:-} == "" ]] || command="MODES=\"${MODES}\" $command"
[[ $keep_awake == both ]] || command="KEEP_AWAKE=$keep_awake $command"
start=$SECONDS
/usr/bin/python3 "$here/formation_scale.py" run --results "$results" \
  --sizes "${sizes[@]}" --modes "${modes[@]}" --window "$window" --rate "$rate" --port "$port" \
  --keep-awake "$keep_awake"
wall=$((SECONDS - start))
/usr/bin/python3 "$here/formation_scale.py" report --results "$results" \
  --md "$out/formation_scale.md" --png "$out/formation_scale.png" --port "$port" \
  --command "$command" --wall "$((wall / 60)) min $((wall % 60)) s wall time"
echo "formation_scale: raw results (one JSON line per launch) in $results"
