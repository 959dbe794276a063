#!/usr/bin/env bash
# The main job: sets up, builds, and runs the paper's two simulation runs with cf_sim, then
# plots them side by side. Results in out/ (or $OUT_DIR): run1.csv, run2.csv, paper_runs.png.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${OUT_DIR:-$root/out}

"$root/scripts/setup.sh"
"$root/scripts/build.sh"
cf_sim=$root/build/devel/lib/projection_collision_avoidance/cf_sim

mkdir -p "$out"
for run in 1 2; do
  echo "Run $run ($( [[ $run == 1 ]] && echo "tracker off" || echo "tracker on" )):"
  "$cf_sim" "$root/config/scenarios/paper_run$run.yaml" --csv "$out/run$run.csv"
done
/usr/bin/python3 "$root/scripts/plot_run.py" "$out/run1.csv" "$out/run2.csv" \
  --title "Run 1: CF tracker off" --title "Run 2: CF tracker on" -o "$out/paper_runs.png"
echo "demo: wrote $out/run1.csv, $out/run2.csv and $out/paper_runs.png"
