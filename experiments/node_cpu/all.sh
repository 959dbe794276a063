#!/usr/bin/env bash
# Reruns every figure of doc/node_cpu.md, in this order:
#   1. builds this checkout (build/) and the commit before the ROS-layer changes (BEFORE, default
#      4aa92ef, checked out with `git worktree` into $WORK/before and built there);
#   2. follower_node, plant_node and leader_node CPU per tick, before and after, at 100 Hz and
#      1 kHz (run.sh) -> doc/node_cpu.csv, and this build's follower with ~trigger timer and
#      measurement, with ~transport udp, and a bare roscpp relay in its place (floor.launch)
#      -> doc/node_cpu_trigger.csv;
#      each follower's CPU by thread (threads.py) -> doc/performance_data/node_cpu_threads.md;
#   3. instructions per tick of each part, before and after (callgrind.sh) ->
#      doc/performance_data/callgrind_{before,after}.txt;
#   4. the platoon in one nodelet manager against N (platoon_cpu.py) -> doc/platoon_cpu.csv and
#      doc/platoon_cpu.png, raw in doc/performance_data/platoon_cpu.jsonl; then N = 128 four times
#      -> doc/platoon_cpu_128_repeats.csv.
# Usage: experiments/node_cpu/all.sh   (BEFORE, WORK (default /tmp/node_cpu), WINDOW (s, default
#   20), SIZES (default "1 8 32 64 96 128 160 192 224 256"), SKIP_BEFORE=1 measures this build
#   alone)
# Took 18 min on this 2-core VM with BEFORE already built (building it: 2.5 min; with
# SKIP_BEFORE=1, none): 6 for step 2, 2 for step 3, 10 for step 4 (plus building this checkout if
# it is not built). On a slower day of the same VM its parts added up to 50 min.
# Timing-sensitive: run it on an otherwise idle machine.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
before=${BEFORE:-4aa92ef}
work=${WORK:-/tmp/node_cpu}
window=${WINDOW:-20}
read -r -a sizes <<<"${SIZES:-1 8 32 64 96 128 160 192 224 256}"
data=$root/doc/performance_data
mkdir -p "$work" "$data"
start=$(date +%s)
step() { echo "node_cpu/all.sh: $* ($(($(date +%s) - start)) s)"; }

step "1. building this checkout"
bash "$root/scripts/build.sh" >"$work/build_after.log"
builds=("after=$root/build")
if [ -z "${SKIP_BEFORE:-}" ]; then
  step "1. building $before into $work/before"
  if [ ! -d "$work/before" ]; then
    git -C "$root" worktree add --detach "$work/before" "$before" >/dev/null
  fi
  BUILD_DIR=$work/before/build bash "$work/before/scripts/build.sh" >"$work/build_before.log"
  builds=("before=$work/before/build" "${builds[@]}")
fi

step "2. CPU per tick: ${builds[*]}"
RUNS=1 WINDOW=$window OUT=$root/doc/node_cpu.csv RAW=$data/node_cpu.jsonl \
  bash "$here/run.sh" "${builds[@]}"
(
  set +u  # the workspace's setup scripts read unset variables
  # shellcheck disable=SC1091
  source "$root/build/devel/setup.bash"
  set -u
  rm -f "$work/trigger.jsonl"
  /usr/bin/python3 "$here/node_cpu.py" --label timer --window "$window" --json "$work/trigger.jsonl"
  /usr/bin/python3 "$here/node_cpu.py" --label "trigger measurement" --window "$window" \
    --launch-arg trigger:=measurement --json "$work/trigger.jsonl"
  /usr/bin/python3 "$here/node_cpu.py" --label "transport udp" --window "$window" \
    --launch-arg transport:=udp --json "$work/trigger.jsonl"
  /usr/bin/python3 "$here/node_cpu.py" --label "roscpp relay (floor)" --floor --window "$window" \
    --json "$work/trigger.jsonl"
  cp "$work/trigger.jsonl" "$data/node_cpu_trigger.jsonl"
  /usr/bin/python3 "$here/node_cpu.py" --report --json "$work/trigger.jsonl" \
    --csv "$root/doc/node_cpu_trigger.csv"
  /usr/bin/python3 "$here/threads.py" "$data/node_cpu.jsonl" "$data/node_cpu_trigger.jsonl" \
    >"$data/node_cpu_threads.md"
)

step "3. instructions per part"
for spec in "${builds[@]}"; do
  bash "$here/callgrind.sh" "${spec#*=}" "$data/callgrind_${spec%%=*}.txt" 1000 40 >/dev/null
done

step "4. the platoon against N = ${sizes[*]}"
(
  set +u
  # shellcheck disable=SC1091
  source "$root/build/devel/setup.bash"
  set -u
  rm -f "$data/platoon_cpu.jsonl" "$data/platoon_cpu_128_repeats.jsonl"
  /usr/bin/python3 "$here/platoon_cpu.py" run --sizes "${sizes[@]}" --window "$window" \
    --json "$data/platoon_cpu.jsonl" --work "$work"
  /usr/bin/python3 "$here/platoon_cpu.py" report --json "$data/platoon_cpu.jsonl" \
    --csv "$root/doc/platoon_cpu.csv" --png "$root/doc/platoon_cpu.png"
  # N = 128 again, four times: how much it varies from run to run.
  /usr/bin/python3 "$here/platoon_cpu.py" run --sizes 128 128 128 128 --window "$window" \
    --json "$data/platoon_cpu_128_repeats.jsonl" --work "$work"
  /usr/bin/python3 "$here/platoon_cpu.py" report --json "$data/platoon_cpu_128_repeats.jsonl" \
    --csv "$root/doc/platoon_cpu_128_repeats.csv" --png "$work/platoon_cpu_128_repeats.png"
)
step "done: doc/node_cpu.csv, doc/node_cpu_trigger.csv, doc/performance_data/callgrind_*.txt," \
  "doc/platoon_cpu.csv, doc/platoon_cpu.png, doc/platoon_cpu_128_repeats.csv"
