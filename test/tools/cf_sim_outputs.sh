#!/usr/bin/env bash
# Runs cf_sim on the scenarios of config/scenarios (sampled; continuous RK4 at 1 and 5 ms; RK6 at
# 10 ms; an acceleration limit acting; shared leader information; a sweep) and writes each
# summary line (without wall_s) and CSV into OUT. Two OUT directories made by two builds compare
# with `diff -r` (the outputs of one commit against another's).
# Usage: cf_sim_outputs.sh CF_SIM OUT
set -euo pipefail
bin=$1
out=$2
root=${ROOT:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}
S=$root/config/scenarios
mkdir -p "$out"
run() {
  local name=$1
  shift
  local status=0
  "$bin" "$@" --csv "$out/$name.csv" > "$out/$name.raw" 2>&1 || status=$?
  # A run cf_sim refuses (exit 2, the key named) is an output too: its message and exit status.
  sed -E 's/ wall_s=[0-9.e+-]+//' "$out/$name.raw" > "$out/$name.txt"
  rm -f "$out/$name.raw"
  echo "exit=$status" >> "$out/$name.txt"
}
L=(--set controller.leader_information.command=true --set controller.leader_information.estimator=true
   --set controller.leader_information.disturbance=true)
for f in paper_run1 paper_run2 figure_eight_2d figure_eight_3d platoon_run2; do
  run "$f.sampled" "$S/$f.yaml"
  run "$f.cont0.001" "$S/$f.yaml" --continuous 0.001
  run "$f.cont0.005" "$S/$f.yaml" --continuous 0.005
  run "$f.rk6" "$S/$f.yaml" --continuous 0.01 --method rk6
  run "$f.sat.sampled" "$S/$f.yaml" --set controller.acceleration_limit=1.0
  run "$f.sat.cont" "$S/$f.yaml" --set controller.acceleration_limit=1.0 --continuous 0.001
  run "$f.shared.sampled" "$S/$f.yaml" "${L[@]}"
  run "$f.shared.cont" "$S/$f.yaml" "${L[@]}" --continuous 0.001
done
run run2_jerk.sampled "$S/paper_run2.yaml" --set controller.acceleration_limit=3 --set controller.jerk_limit=20
"$bin" "$S/paper_run2.yaml" --sweep "$out/sweep.csv" --directions 4 --max-size 6 --size-step 1 2>&1 |
  sed -E 's/ wall_s=[0-9.e+-]+//' > "$out/sweep.txt"
