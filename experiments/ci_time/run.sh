#!/usr/bin/env bash
# Times CI's command: scripts/test.sh on a clean clone of the committed HEAD in a brand-new Debian
# 12 root (../shared/tools/fresh-debian-run, as .ci/run does; root only), each line of its output
# stamped with the Unix time it was printed, kept as doc/ci_time/LABEL.log.gz; then the phases.
# Usage: experiments/ci_time/run.sh LABEL [--keep]
#   --keep  keep the root (/var/tmp/fresh-debian-ci-time) for a look at its build folders
# The table of doc/testing.md: experiments/ci_time/ci_phases.py report --before
#   doc/ci_time/before.log.gz --after doc/ci_time/after.log.gz --update doc/testing.md
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
label=${1:?usage: experiments/ci_time/run.sh LABEL [--keep]}
keep=()
[[ ${2:-} == --keep ]] && keep=(--keep)
fresh=$root/../shared/tools/fresh-debian-run
[[ -x $fresh ]] || { echo "ci_time: $fresh not found" >&2; exit 2; }
mkdir -p "$root/doc/ci_time"
log=$root/doc/ci_time/$label.log
status=0
(cd "$root" && "$fresh" "${keep[@]}" --root /var/tmp/fresh-debian-ci-time -- bash scripts/test.sh) 2>&1 |
  while IFS= read -r line; do printf '%s %s\n' "$(date +%s)" "$line"; done >"$log" || status=$?
gzip -f "$log"
/usr/bin/python3 "$here/ci_phases.py" phases "$log.gz"
echo "ci_time: $log.gz (exit $status)"
exit "$status"
