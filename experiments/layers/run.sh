#!/usr/bin/env bash
# Lines of code per layer (include/projection_collision_avoidance/<layer> and src/<layer>; the
# follower's cycle was called node/ before it was cycle/) and the largest source file, at each
# git revision given (default HEAD), as a markdown table on stdout.
# Usage: bash experiments/layers/run.sh [REV ...]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
[[ $# -gt 0 ]] || set -- HEAD
lines() {  # REV PATH... -> total lines of the files under the paths at REV
  local rev=$1
  shift
  git ls-tree -r --name-only "$rev" -- "$@" | while read -r f; do git show "$rev:$f"; done | wc -l
}
inc=include/projection_collision_avoidance
printf '| layer |'
for rev in "$@"; do printf ' %s |' "$(git rev-parse --short "$rev")"; done
printf '\n|---|'
for _ in "$@"; do printf -- '---:|'; done
printf '\n'
for layer in core configuration sim scenario vehicle rt cycle ros; do
  printf '| %s |' "$layer"
  for rev in "$@"; do
    if [[ $layer == cycle ]]; then
      n=$(lines "$rev" "$inc/cycle" src/cycle "$inc/node" src/node)
    else
      n=$(lines "$rev" "$inc/$layer" "src/$layer")
    fi
    printf ' %s |' "$n"
  done
  printf '\n'
done
printf '| largest source file |'
for rev in "$@"; do
  largest=$(git ls-tree -r --name-only "$rev" -- src "$inc" | while read -r f; do
    printf '%s %s\n' "$(git show "$rev:$f" | wc -l)" "$f"
  done | sort -rn | awk 'NR == 1')
  printf ' %s |' "$largest"
done
printf '\n'
