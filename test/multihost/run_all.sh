#!/usr/bin/env bash
# The multi-host cases (test/multihost/hosts.sh), one after the other, written as JUnit XML
# (RESULTS_DIR/multihost.xml) so that catkin_test_results and scripts/test.sh count them. A case
# the machine cannot run (not root, no namespaces) is written as skipped with the reason, never as
# passed. The "refused" case expects the run to fail: a follower host 2 s ahead judged on its
# stamps has its measurements refused as stale (and its commands would be refused by the plant).
# Usage: test/multihost/run_all.sh BUILD_DIR RESULTS_DIR [CASE...]   (default: every case)
# Environment: MULTIHOST_JOBS, how many cases run at once (default 1).
set -uo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
build=${1:?build dir}
results=${2:?results dir}
shift 2
wall=(sim_time:=false end_time:=30)
# On wall time the cases compare with cf_sim; a follower that brakes because its host stalled
# (a loaded CI machine: 0.5 s without a callback) departs from it. Their inputs' timeouts are 1.5 s,
# still below the 2 s a wrong clock correction would add to every age. The braking fallback has
# tests of its own (test/rostest/faults.test), and the refused case keeps the 0.5 s default.
stall=(measurement_timeout:=1.5 leader_timeout:=1.5)
estimate=(clock_skew_policy:=estimate plant_clock_skew_policy:=estimate)
receipt=(clock_skew_policy:=receipt plant_clock_skew_policy:=receipt)
declare -A cases=(
  [pair_sim_time]="pair"
  [pair_udp]="pair transport:=udp"
  [pair_ahead_30ms_stamps]="pair --clocks +0.03s ${wall[*]} ${stall[*]}"
  [pair_behind_30ms_stamps]="pair --clocks -0.03s ${wall[*]} ${stall[*]}"
  [pair_ahead_2s_estimate]="pair --clocks +2s ${wall[*]} ${estimate[*]} ${stall[*]}"
  [pair_behind_2s_estimate]="pair --clocks -2s ${wall[*]} ${estimate[*]} ${stall[*]}"
  [pair_ahead_2s_receipt]="pair --clocks +2s ${wall[*]} ${receipt[*]} ${stall[*]}"
  [pair_ahead_2s_stamps_refused]="pair --clocks +2s ${wall[*]} wall_deadline:=20"
  [formation_sim_time]="formation"
  [formation_skewed_estimate]="formation --clocks +1.5s,-0.7s,+0.04s ${wall[*]} ${estimate[*]} ${stall[*]}"
)
order=(pair_sim_time pair_udp pair_ahead_30ms_stamps pair_behind_30ms_stamps)
order+=(pair_ahead_2s_estimate pair_behind_2s_estimate pair_ahead_2s_receipt)
order+=(pair_ahead_2s_stamps_refused formation_sim_time formation_skewed_estimate)
[[ $# -gt 0 ]] && order=("$@")

mkdir -p "$results"
xml=$results/multihost.xml
for name in "${order[@]}"; do
  [[ -n ${cases[$name]:-} ]] || { echo "unknown case $name" >&2; exit 2; }
done
# Every case has hosts of its own (namespaces named by its process id, a master in each): up to
# $MULTIHOST_JOBS of them run at once.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The cases must leave the machine as they found it: no namespace of theirs and /run/netns a mount
# point only if it was one before (a mount left behind keeps CI's root from being removed).
mounts_before=$(mountpoint -q /run/netns 2>/dev/null && echo mounted || echo none)
run_case() {
  local name=$1 logdir=$work/$1 start=$SECONDS kind rest
  mkdir -p "$logdir"
  read -r kind rest <<<"${cases[$name]}"
  # shellcheck disable=SC2086
  bash "$here/hosts.sh" "$build" "$kind" --log "$logdir" $rest >"$logdir/run.log" 2>&1
  echo "$? $((SECONDS - start))" >"$logdir/result"
}
running=0
for name in "${order[@]}"; do
  if [[ $running -ge ${MULTIHOST_JOBS:-1} ]]; then
    wait -n
    running=$((running - 1))
  fi
  run_case "$name" &
  running=$((running + 1))
done
wait

body=""
failures=0
skipped=0
for name in "${order[@]}"; do
  logdir=$work/$name
  read -r rc seconds <"$logdir/result"
  outcome=passed
  if [[ $rc == 77 ]]; then
    outcome="skipped: $(grep -m1 '^skipped:' "$logdir/run.log" | cut -c10-)"
    body+="  <testcase classname=\"multihost\" name=\"$name\" time=\"$seconds\"><skipped message=\"${outcome#skipped: }\"/></testcase>"$'\n'
    skipped=$((skipped + 1))
  elif [[ $name == *_refused ]]; then
    if [[ $rc == 1 ]] && grep -q "relative_measurement rejected: stale" "$logdir"/follower_*.log; then
      body+="  <testcase classname=\"multihost\" name=\"$name\" time=\"$seconds\"/>"$'\n'
    else
      outcome="FAILED: expected the run to fail with the measurements refused as stale (exit $rc)"
      body+="  <testcase classname=\"multihost\" name=\"$name\" time=\"$seconds\"><failure message=\"$outcome\"/></testcase>"$'\n'
      failures=$((failures + 1))
    fi
  elif [[ $rc == 0 ]]; then
    body+="  <testcase classname=\"multihost\" name=\"$name\" time=\"$seconds\"/>"$'\n'
  else
    outcome="FAILED (exit $rc)"
    tail -40 "$logdir/run.log"
    body+="  <testcase classname=\"multihost\" name=\"$name\" time=\"$seconds\"><failure message=\"exit $rc\"/></testcase>"$'\n'
    failures=$((failures + 1))
  fi
  echo "multihost $name: $outcome ($seconds s) [${cases[$name]}]"
  grep -rh "ROS run:\|ROS max" "$logdir/ros" 2>/dev/null | sed 's/.*\(ROS run:\|follower_[0-9]* ->\)/    \1/' | sed 's/\x1b\[[0-9;]*m//g' | sort -u || true
done
mounts_after=$(mountpoint -q /run/netns 2>/dev/null && echo mounted || echo none)
left=$(ip netns list 2>/dev/null | grep -c "^pca" || true)
if [[ $mounts_after == "$mounts_before" ]] && [[ $left == 0 ]]; then
  body+="  <testcase classname=\"multihost\" name=\"cleaned_up\" time=\"0\"/>"$'\n'
  echo "multihost cleaned_up: passed (/run/netns $mounts_after as before, no namespace left)"
else
  outcome="/run/netns $mounts_before before and $mounts_after after, $left namespaces left"
  body+="  <testcase classname=\"multihost\" name=\"cleaned_up\" time=\"0\"><failure message=\"$outcome\"/></testcase>"$'\n'
  echo "multihost cleaned_up: FAILED ($outcome)"
  failures=$((failures + 1))
fi
{
  echo '<?xml version="1.0" encoding="UTF-8"?>'
  echo "<testsuite name=\"multihost\" tests=\"$((${#order[@]} + 1))\" failures=\"$failures\" skipped=\"$skipped\" errors=\"0\">"
  printf '%s' "$body"
  echo '</testsuite>'
} >"$xml"
[[ $failures == 0 ]]
