#!/usr/bin/env bash
# Installs the Debian 12 packages this package needs that are missing, and nothing else.
# Usage: scripts/setup.sh [--workspace-tools]
#   --workspace-tools  also catkin-tools and colcon, for the catkin workspace builds
# Runs apt-get as root, through sudo when not root.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  catkin python3-catkin-pkg catkin-lint
  libeigen3-dev libyaml-cpp-dev libyaml-dev
  googletest libgtest-dev libbenchmark-dev
  clang libclang-rt-14-dev llvm  # scripts/sanitize.sh: ASan, UBSan, libFuzzer, llvm-symbolizer
  python3-yaml python3-numpy python3-scipy python3-matplotlib
  ros-core-dev libtf2-ros-dev libtf2-eigen-dev libdiagnostic-updater-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  libnodeletlib-dev libnodeletlib-tools pluginlib-dev
  python3-rostest python3-rosbag librosbag-dev rviz xvfb
)
if [[ "${1:-}" == "--workspace-tools" ]]; then
  packages+=(catkin-tools colcon python3-colcon-ros)
fi

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if [[ ${#missing[@]} -eq 0 ]]; then
  echo "setup: every package is installed"
  exit 0
fi

as_root=()
if [[ $(id -u) -ne 0 ]]; then
  as_root=(sudo)
fi
echo "setup: installing ${missing[*]}"
"${as_root[@]}" apt-get update -q
DEBIAN_FRONTEND=noninteractive "${as_root[@]}" apt-get install -y -q --no-install-recommends \
  "${missing[@]}"
