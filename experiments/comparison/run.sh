#!/usr/bin/env bash
# The paper's CF estimator and tracker beside the control barrier function filter
# (controller.safety_filter) on the same scenarios and pushes, through cf_sim: writes OUT_DIR
# (default doc/) comparison.csv, comparison_sweep.csv and comparison_tables.md (also placed in
# doc/comparison.md between its markers).
# Usage: experiments/comparison/run.sh [OUT_DIR] [--quick]   (a few minutes after the build)
# Builds first (BUILD_DIR as for scripts/build.sh), unless CF_SIM=path/to/cf_sim is given.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${1:-$root/doc}
# shellcheck source=experiments/common/cf_sim_path.bash
source "$root/experiments/common/cf_sim_path.bash"
find_cf_sim comparison "$root"
/usr/bin/python3 "$here/comparison_table.py" "$CF_SIM" "$out" "${@:2}"
echo "comparison: wrote $out/comparison.csv, comparison_sweep.csv, comparison_tables.md"
