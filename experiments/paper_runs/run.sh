#!/usr/bin/env bash
# Regenerates the figures in doc/ from cf_sim runs of the paper's scenario:
#   doc/paper_runs.png       Run 1 (tracker off) and Run 2 (tracker on) side by side, 0-60 s
#   doc/paper_runs_zoom.png  the same, 15-35 s around the disturbance
# Usage: experiments/paper_runs/run.sh   (builds first; BUILD_DIR as for scripts/build.sh)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build_dir=${BUILD_DIR:-$root/build}
BUILD_DIR=$build_dir "$root/scripts/build.sh" >/dev/null
cf_sim=$build_dir/devel/lib/projection_collision_avoidance/cf_sim

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for run in 1 2; do
  "$cf_sim" "$root/config/scenarios/paper_run$run.yaml" --csv "$work/run$run.csv"
done
titles=(--title "Run 1: CF tracker off" --title "Run 2: CF tracker on")
/usr/bin/python3 "$root/scripts/plot_run.py" "$work/run1.csv" "$work/run2.csv" "${titles[@]}" \
  -o "$root/doc/paper_runs.png"
/usr/bin/python3 "$root/scripts/plot_run.py" "$work/run1.csv" "$work/run2.csv" "${titles[@]}" \
  --xlim 15 35 -o "$root/doc/paper_runs_zoom.png"
echo "wrote doc/paper_runs.png and doc/paper_runs_zoom.png"
