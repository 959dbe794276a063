#!/usr/bin/env bash
# The follower and the unicycle command adapter driving robots of a third-party simulator (Enki,
# test/enki/enki_bridge.py), case by case: vehicle (thymio2, epuck) x the follower's input
# (odometry, tf, position) x Enki's physics step (0.01, 0.05, 0.1 s) x the follower's initial
# heading relative to the leader's (0, 90, 180 degrees) x the leader's push (x1, x2). Each case is
# a run of test/enki/enki_sweep.launch of 25 s on wall time on its own ROS master (about 35 s
# wall), one after the other; enki_sweep.py computes per case max ||xi|| against xi_max, the
# closest controlled points and robot centres against the perimeter, and the realised against the
# commanded acceleration, and writes
#   doc/vehicles_enki.csv, doc/vehicles_enki.md   (or --csv, --md)
# Usage: experiments/enki_sweep/run.sh [--cases quick|full] [enki_sweep.py options ...]
#   --cases quick (default) runs 5 cases (about 3 min), full the 108 of the product (about 1 h);
#   --vehicles, --inputs, --steps, --headings, --pushes narrow the full product;
#   --keep DIR keeps the bags and launch logs. ROS port: --port (default 11431).
#   Needs a built workspace: DEVEL_SETUP=path/to/devel/setup.bash, default build/devel/setup.bash
#   (scripts/build.sh), and Debian's python3-enki2.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
case ${1:-} in -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;; esac
setup=${DEVEL_SETUP:-$root/build/devel/setup.bash}
test -f "$setup" || { "$root/scripts/build.sh" >/dev/null; setup=$root/build/devel/setup.bash; }
set +u  # the workspace's setup scripts read unset variables
# shellcheck disable=SC1090
source "$setup"
set -u
exec /usr/bin/python3 "$here/enki_sweep.py" "$@"
