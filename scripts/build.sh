#!/usr/bin/env bash
# Configures and builds the package standalone (no workspace) into build/ (or $BUILD_DIR).
# Usage: scripts/build.sh [extra make targets...]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${BUILD_DIR:-$root/build}

# Debian's catkin runs on Debian's python3, whatever python3 comes first on PATH.
cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCATKIN_ENABLE_TESTING=ON >/dev/null
make -C "$build_dir" -j"$(nproc)" all "$@"
# catkin caches the devel environment at configure time, keeping only directories that exist
# then: configure once more so that it includes the generated Python messages (the Python
# rostests import them).
cmake "$build_dir" >/dev/null
