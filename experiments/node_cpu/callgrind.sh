#!/usr/bin/env bash
# Instructions per control tick of each part of follower_node, from callgrind: pair.launch (Run 2,
# real time) at RATE Hz with the follower under valgrind --tool=callgrind for SECONDS wall
# seconds, then callgrind_annotate's inclusive counts of the functions named in
# callgrind_parts.py (beside this script), divided by the ticks run.
# Usage: experiments/node_cpu/callgrind.sh BUILD_DIR OUT.txt [RATE] [SECONDS]   (default 1000, 40)
# The follower runs about 50 times slower under valgrind, so it keeps fewer ticks than RATE asks;
# counts per tick do not depend on that. Needs valgrind.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
[ $# -ge 2 ] || { sed -n '2,8p' "${BASH_SOURCE[0]}"; exit 2; }
build=$(cd "$1" && pwd)
out=$2
rate=${3:-1000}
seconds=${4:-40}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
[ -z "${KEEP:-}" ] || trap - EXIT
set +u  # the workspace's setup scripts read unset variables
# shellcheck disable=SC1091
source "$build/devel/setup.bash"
set -u
export ROS_MASTER_URI=http://localhost:11433
prefix="valgrind --tool=callgrind --callgrind-out-file=$work/callgrind.out.%p --dump-instr=no"
# This checkout's pair.launch (it has follower_prefix), the nodes of BUILD_DIR.
# One run of the launch; its profile is complete once callgrind wrote its totals at the
# follower's exit (roslaunch kills a node that takes too long to end, and a killed follower
# leaves a truncated profile: then the run is repeated, at most three times in all).
for attempt in 1 2 3; do
  rm -f "$work"/callgrind.out.*
  # This checkout's pair.launch (it has follower_prefix), the nodes of BUILD_DIR.
  setsid roslaunch --port 11433 "$root/launch/pair.launch" \
    scenario:="$root/config/scenarios/paper_run2.yaml" sim_time:=false control_rate:="$rate" \
    follower_prefix:="$prefix" >"$work/launch.log" 2>&1 &
  launch=$!
  sleep "$seconds"
  kill -INT "$launch"
  wait "$launch" || true
  file=$(ls "$work"/callgrind.out.* 2>/dev/null | head -1)
  if [ -n "$file" ] && grep -q '^totals:' "$file"; then
    break
  fi
  echo "callgrind.sh: run $attempt left no complete profile" >&2
  file=
done
[ -n "$file" ] || exit 1
callgrind_annotate --inclusive=yes --threshold=100 "$file" >"$work/annotate.txt"
/usr/bin/python3 "$here/callgrind_parts.py" "$work/annotate.txt" "$file" | tee "$out"
