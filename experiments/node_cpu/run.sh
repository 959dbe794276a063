#!/usr/bin/env bash
# CPU time per control tick of follower_node, plant_node and leader_node under pair.launch
# (Run 2, real time) at 100 Hz and 1 kHz, read from /proc (node_cpu.py beside this script), for
# one or more builds measured in turn (for instance the commit before a change and after it).
# Writes doc/node_cpu.csv and prints the table.
# Usage: experiments/node_cpu/run.sh [LABEL=BUILD_DIR ...]   (default: current=build)
#   WINDOW (default 30 s per measurement), RUNS (default 2 rounds over the builds), OUT (default
#   doc/node_cpu.csv), RAW (the JSON lines of every measurement; default a temporary file).
#   About (15 + WINDOW) s per build, rate and round: 6 min with the defaults
#   for two builds. Timing-sensitive: run it on an otherwise idle machine.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
window=${WINDOW:-30}
runs=${RUNS:-2}
out=${OUT:-$root/doc/node_cpu.csv}
builds=("$@")
((${#builds[@]})) || builds=("current=$root/build")
results=${RAW:-$(mktemp --suffix=.jsonl)}
rm -f "$results"
for ((run = 1; run <= runs; run++)); do
  for spec in "${builds[@]}"; do
    label=${spec%%=*}
    build=${spec#*=}
    test -f "$build/devel/setup.bash" || { echo "node_cpu: no $build/devel/setup.bash" >&2; exit 2; }
    (
      set +u  # the workspace's setup scripts read unset variables
      # shellcheck disable=SC1091
      source "$build/devel/setup.bash"
      set -u
      /usr/bin/python3 "$here/node_cpu.py" --label "$label" --window "$window" --json "$results"
    )
  done
done
/usr/bin/python3 "$here/node_cpu.py" --report --json "$results" --csv "$out"
echo "node_cpu: raw results in $results, table in $out"
