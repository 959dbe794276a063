#!/usr/bin/env bash
# The runs of the neighbour table against time: V stars of 4, 16 and 64 in seeded random gusts
# (config/scenarios/crowd_16_gusts.yaml, seed 1 unless --seed), without and with
# formation.neighbours; the smallest distance over every pair against the perimeter and the
# largest ||xi_i|| / xi_max,i (plot_runs.py). Writes OUT_PNG (default doc/neighbours_runs.png).
# Usage: experiments/neighbours/plot_runs.sh [--seed S] [OUT_PNG]   (half a minute: 6 cf_sim runs)
# Builds first (BUILD_DIR as for scripts/build.sh), unless CF_SIM=path/to/cf_sim is given.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
seed=1
out=$root/doc/neighbours_runs.png
while [ $# -gt 0 ]; do
  case "$1" in
    --seed) seed=$2; shift 2 ;;
    -*) echo "usage: $0 [--seed S] [OUT_PNG]" >&2; exit 2 ;;
    *) out=$1; shift ;;
  esac
done
# shellcheck source=experiments/common/cf_sim_path.bash
source "$root/experiments/common/cf_sim_path.bash"
find_cf_sim neighbours "$root"
/usr/bin/python3 "$here/plot_runs.py" "$CF_SIM" "$out" --seed "$seed"
echo "neighbours: wrote $out"
