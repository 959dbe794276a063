#!/usr/bin/env bash
# Builds the package in a fresh workspace DIR/TOOL the way README's workspace route does (the
# package linked into src/, -DPYTHON_EXECUTABLE=/usr/bin/python3), compiling through ccache.
# Usage: scripts/workspace.sh colcon|catkin_make|catkin_build DIR [--tests]
#   --tests  also build the tests in the package's build folder (its ctest then runs them)
# Prints the package's build folder; the build's output goes to DIR/TOOL/build.log.
# ccache: CMake's CMAKE_<LANG>_COMPILER_LAUNCHER from the environment (the command lines stay
# README's), CCACHE_BASEDIR=DIR: workspaces side by side in DIR compile each file from the same
# relative place, so that one finds what another compiled (the cache is ccache's default one, or
# $CCACHE_DIR). MAKEFLAGS (default -j<cores>) keeps catkin_make and colcon from throttling make
# by the load average.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
package=projection_collision_avoidance
tool=${1:?usage: workspace.sh colcon|catkin_make|catkin_build DIR [--tests]}
dir=${2:?usage: workspace.sh colcon|catkin_make|catkin_build DIR [--tests]}
tests=${3:-}
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
ws=$dir/$tool
rm -rf "$ws"
mkdir -p "$ws/src"
ln -s "$root" "$ws/src/$package"
export CMAKE_C_COMPILER_LAUNCHER=ccache CMAKE_CXX_COMPILER_LAUNCHER=ccache
export CCACHE_BASEDIR=$dir CCACHE_NOHASHDIR=1
export MAKEFLAGS=${MAKEFLAGS:--j$(nproc)}
cd "$ws"
case $tool in
  colcon)
    colcon build --cmake-args -DPYTHON_EXECUTABLE=/usr/bin/python3 >build.log 2>&1
    build=$ws/build/$package ;;
  catkin_make)
    catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 >build.log 2>&1
    build=$ws/build/$package ;;
  catkin_build)
    {
      catkin init && catkin config --cmake-args -DPYTHON_EXECUTABLE=/usr/bin/python3 &&
        catkin build --no-status
    } >build.log 2>&1
    build=$ws/build/$package ;;
  *) echo "workspace: unknown tool $tool (colcon, catkin_make or catkin_build)" >&2; exit 2 ;;
esac || { tail -40 build.log >&2; echo "workspace: $tool failed (log: $ws/build.log)" >&2; exit 1; }
if [[ $tests == --tests ]]; then
  make -C "$build" tests >>build.log 2>&1 || {
    tail -40 build.log >&2; echo "workspace: building the tests failed (log: $ws/build.log)" >&2
    exit 1
  }
  # catkin caches the devel environment at configure time, keeping only directories that exist
  # then: configure once more so that it includes the generated Python messages (the Python
  # rostests import them).
  cmake "$build" >>build.log
fi
echo "$build"
