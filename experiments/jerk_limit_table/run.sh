#!/usr/bin/env bash
# The table of doc/faults.md on controller.jerk_limit: Run 2 (config/scenarios/paper_run2.yaml,
# 1 kHz) at several jerk limits, with and without an acceleration limit of 6 m/s^2: max ||xi||
# and min separation from cf_sim's summary line. Prints a Markdown table (a second of cf_sim).
# Usage: experiments/jerk_limit_table/run.sh   (builds first, unless CF_SIM=path/to/cf_sim is
#   given)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
# shellcheck source=experiments/common/cf_sim_path.bash
source "$root/experiments/common/cf_sim_path.bash"
find_cf_sim jerk_limit_table "$root"

field() { sed -n "s/.*$1=\([^ ]*\).*/\1/p" <<<"$2"; }
echo "| J (m/s³) | max ‖ξ‖ (m) | min separation (m) | with acceleration_limit 6: max ‖ξ‖ (m) | min separation (m) |"
echo "|---|---|---|---|---|"
for jerk in .inf 200 100 50 20 10 5 2; do
  row="| $jerk"
  for limit in .inf 6; do
    line=$("$CF_SIM" "$root/config/scenarios/paper_run2.yaml" --set "controller.jerk_limit=$jerk" \
      --set "controller.acceleration_limit=$limit")
    row+=" | $(printf '%.4g' "$(field max_xi "$line")") | $(printf '%.4g' "$(field min_separation "$line")")"
  done
  echo "$row |"
done
