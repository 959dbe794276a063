#!/usr/bin/env bash
# A rostest across hosts made of network namespaces (test/multihost/netns.sh). Host "world"
# (10.231.0.1) runs the master, the plant, the leader and the test; follower host i
# (10.231.0.(1+i)) runs follower i alone; each host has its own ROS_IP. A follower host's clock
# can be offset (libfaketime): --clocks "+2s,-0.03s" puts follower host 1 two seconds ahead and
# host 2 30 ms behind ("" or 0 leaves a host's clock alone).
# Needs root; where namespaces cannot be made it says "skipped: why" and exits 77. Everything it
# makes (namespaces, links, processes, its log directory) is removed on exit, also on failure.
#
# Usage: test/multihost/hosts.sh BUILD_DIR pair|formation [--followers N] [--clocks LIST]
#          [--log DIR] [launch args for every host...]
#   pair       Run 2 (test/rostest/paper_run2.test): the follower on its own host
#   formation  test/rostest/formation.test with N followers (default 3) in a chain, each on its host
#              (launch/fleet_follower.launch there)
#   --log DIR  keep the hosts' logs there (default: a temporary directory, removed on exit)
# e.g. test/multihost/hosts.sh build pair --clocks +2s sim_time:=false \
#        clock_skew_policy:=estimate plant_clock_skew_policy:=estimate
set -eo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
build=${1:?build dir}
kind=${2:?pair or formation}
shift 2
followers=1
[[ $kind == formation ]] && followers=3
clocks=""
keep_log=""
while [[ $# -gt 0 && $1 == --* ]]; do
  case $1 in
    --followers) followers=$2; shift 2 ;;
    --clocks) clocks=$2; shift 2 ;;
    --log) keep_log=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
case $kind in
  pair) [[ $followers == 1 ]] || { echo "pair has one follower" >&2; exit 2; } ;;
  formation) ;;
  *) echo "unknown test $kind (pair or formation)" >&2; exit 2 ;;
esac
IFS=, read -r -a offsets <<<"$clocks"
log=${keep_log:-$(mktemp -d)}
mkdir -p "$log"
# shellcheck disable=SC1091
source "$build/devel/setup.bash"
# shellcheck source=netns.sh
source "$here/netns.sh"
make_hosts "$followers"

faketime_library=$(ls /usr/lib/*/faketime/libfaketime.so.1 2>/dev/null | head -n 1)
[[ $clocks == *[1-9]* && -z $faketime_library ]] && { echo "hosts.sh: libfaketime not found" >&2; exit 2; }
sim_time=sim_time:=true  # the tests' default; fleet_follower.launch's is false (a real fleet)
for a in "$@"; do [[ $a == sim_time:=* ]] && sim_time=$a; done
scenario_dir=$(rospack find projection_collision_avoidance)/config/scenarios
for i in $(seq "$followers"); do
  offset=${offsets[$((i - 1))]:-}
  prefix=()
  # libfaketime preloaded with a fixed offset, not through the faketime wrapper: the wrapper
  # creates a semaphore and shared memory named by its process id in /dev/shm, which a wrapper
  # killed before it cleaned up leaves behind for a later process of the same id to collide with
  # ("sem_open: File exists", the follower never starts).
  [[ -n $offset && $offset != 0 ]] && prefix=(env LD_PRELOAD="$faketime_library" FAKETIME="$offset")
  if [[ $kind == pair ]]; then
    launch=(pair.launch scenario:="$scenario_dir/paper_run2.yaml" world:=false control_rate:=100)
  else
    launch=(fleet_follower.launch index:="$i" scenario:="$scenario_dir/paper_run2.yaml"
      followers:="$followers" topology:=chain shape:=line control_rate:=100 "$sim_time")
  fi
  echo "follower host $i: $(host_address "$i"), clock offset ${offset:-0}"
  on_host "$i" "${prefix[@]}" roslaunch --wait projection_collision_avoidance "${launch[@]}" "$@" \
    >"$log/follower_$i.log" 2>&1 &
done
# The followers listen before the plant starts (on wall time it does not wait for them).
for _ in $(seq 300); do
  n=$(on_host 0 rosnode list 2>/dev/null | grep -c controller || true)
  [[ $n -ge $followers ]] && break
  sleep 0.1
done
if [[ $kind == pair ]]; then
  test_file=paper_run2.test
  test_args=(follower:=false)
else
  test_file=formation.test
  test_args=(followers_here:=false followers:="$followers")
fi
on_host 0 rostest --reuse-master projection_collision_avoidance "$test_file" \
  "${test_args[@]}" "$@" || {
  for i in $(seq "$followers"); do tail -20 "$log/follower_$i.log"; done
  exit 1
}
