#!/usr/bin/env bash
# cf_sim's outputs at a revision against this checkout's: builds REV's cf_sim in a git worktree
# (scripts/build.sh, into BUILD_DIR_BEFORE, default /tmp/pca-cf-sim-REV; or CF_SIM_BEFORE names a
# cf_sim already built at REV; CF_SIM this checkout's, see experiments/common), runs
# test/tools/cf_sim_outputs.sh with both (every scenario of config/scenarios, sampled and
# continuous, limits acting, shared information, a sweep: each run's summary, exit status and
# CSV) and compares the two directories byte for byte. Exits 1 on any difference.
# Usage: bash experiments/cf_sim_outputs/run.sh REV [OUT_DIR]   (OUT_DIR default /tmp/pca-cf-sim)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
rev=${1:?usage: run.sh REV [OUT_DIR]}
out=${2:-/tmp/pca-cf-sim}
short=$(git -C "$root" rev-parse --short "$rev")
before_src=$out/src-$short
before_build=${BUILD_DIR_BEFORE:-/tmp/pca-cf-sim-$short}
# shellcheck source=experiments/common/cf_sim_path.bash
source "$root/experiments/common/cf_sim_path.bash"
find_cf_sim cf_sim_outputs "$root"
after_bin=$CF_SIM
before_bin=${CF_SIM_BEFORE:-}
if [[ -z $before_bin ]]; then
  if [[ ! -d $before_src ]]; then
    mkdir -p "$out"
    git -C "$root" worktree add --detach "$before_src" "$rev" >/dev/null
  fi
  BUILD_DIR=$before_build "$before_src/scripts/build.sh" >/dev/null
  before_bin=$before_build/devel/lib/projection_collision_avoidance/cf_sim
fi
rm -rf "$out/before" "$out/after"
ROOT=$root bash "$root/test/tools/cf_sim_outputs.sh" "$before_bin" "$out/before"
ROOT=$root bash "$root/test/tools/cf_sim_outputs.sh" "$after_bin" "$out/after"
runs=$(find "$out/after" -name '*.txt' | wc -l)
files=$(find "$out/after" -type f | wc -l)
refused=$(grep -l '^exit=[1-9]' "$out/after"/*.txt | wc -l)
if diff -rq "$out/before" "$out/after"; then
  echo "cf_sim at $short and at this checkout: $runs runs ($refused refused alike), $files files, identical byte for byte"
else
  echo "cf_sim at $short and at this checkout differ (above)"
  exit 1
fi
