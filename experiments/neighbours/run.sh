#!/usr/bin/env bash
# Safety from every neighbour: formations of 4, 16 and 64 in a world that can hurt (seeded gusts,
# vehicles apart from the model, measurement noise) and a V of 4 with a gust on one follower; the
# smallest distance over every pair against the perimeter. Writes OUT_DIR (default doc/)
# neighbour_safety.csv and neighbour_safety.md (also placed in formations.md between its markers).
# Usage: experiments/neighbours/run.sh [OUT_DIR]   (about a minute after the build: 17 cf_sim runs).
# Builds first (BUILD_DIR as for scripts/build.sh), unless CF_SIM=path/to/cf_sim is given.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${1:-$root/doc}
# shellcheck source=experiments/common/cf_sim_path.bash
source "$root/experiments/common/cf_sim_path.bash"
find_cf_sim neighbours "$root"
/usr/bin/python3 "$here/neighbours_table.py" "$CF_SIM" "$out"
echo "neighbours: wrote $out/neighbour_safety.csv, neighbour_safety.md"
