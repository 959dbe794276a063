#!/usr/bin/env bash
# Installs the Debian 12 packages of scripts/debian-packages.txt that are missing, and nothing else.
# Usage: scripts/setup.sh [--list | PACKAGE...]
#   --list      print the packages and exit
#   PACKAGE...  only these (each one of the list; scripts/test.sh installs what its sanitizer
#               build needs first, to build beside the rest of the installation)
# Runs apt-get as root, through sudo when not root.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# The first word of each line that is not a comment.
mapfile -t packages < <(sed -e 's/#.*//' -e '/^[[:space:]]*$/d' "$root/scripts/debian-packages.txt" |
  awk '{print $1}')
if [[ "${1:-}" == "--list" ]]; then
  printf '%s\n' "${packages[@]}"
  exit 0
elif [[ "${1:-}" == -* ]]; then
  echo "usage: scripts/setup.sh [--list | PACKAGE...]" >&2
  exit 2
elif [[ $# -gt 0 ]]; then
  for package in "$@"; do
    printf '%s\n' "${packages[@]}" | grep -qxF -- "$package" || {
      echo "setup: $package is not in scripts/debian-packages.txt" >&2; exit 2; }
  done
  packages=("$@")
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
