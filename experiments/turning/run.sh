#!/usr/bin/env bash
# Turning formations: the turning scenarios (config/scenarios/turning_*.yaml, made by
# make_scenarios.py, and figure_eight_2d.yaml), each for a pair, a V star of 4 and a line chain of
# 10, with world-fixed slots, turning slots, and turning slots of a reversing target. Writes to
# OUT_DIR (default doc/): turning_formations.csv (every follower), turning_formations.md (the
# table, also placed in formations.md between its markers) and turning_paths.png.
# Usage: experiments/turning/run.sh [OUT_DIR]   (about a minute after the build: 36 cf_sim runs).
# Builds first (BUILD_DIR as for scripts/build.sh), unless CF_SIM=path/to/cf_sim is given.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${1:-$root/doc}
# shellcheck source=experiments/common/cf_sim_path.bash
source "$root/experiments/common/cf_sim_path.bash"
find_cf_sim turning "$root"
/usr/bin/python3 "$here/make_scenarios.py" >/dev/null
git -C "$root" diff --quiet -- config/scenarios 2>/dev/null ||
  echo "turning: make_scenarios.py changed config/scenarios (see git diff)"
/usr/bin/python3 "$here/turning_table.py" "$CF_SIM" "$out"
echo "turning: wrote $out/turning_formations.csv, turning_formations.md, turning_paths.png"
