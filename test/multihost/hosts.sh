#!/usr/bin/env bash
# A rostest across hosts made of network namespaces. Host "world" (10.231.0.1) runs the master,
# the plant, the leader and the test; follower host i (10.231.0.(1+i)) runs follower i alone. The
# hosts are joined by a bridge on world and a veth pair per follower host; each host has its own
# ROS_IP. A follower host's clock can be offset (libfaketime): --clocks "+2s,-0.03s" puts follower
# host 1 two seconds ahead and host 2 30 ms behind ("" or 0 leaves a host's clock alone).
# Needs root; where namespaces cannot be made it says "skipped: why" and exits 77. Everything it
# makes (namespaces, links, processes, its log directory) is removed on exit, also on failure.
#
# Usage: test/multihost/hosts.sh BUILD_DIR pair|formation [--followers N] [--clocks LIST]
#          [--log DIR] [launch args for every host...]
#   pair       Run 2 (test/ros/paper_run2.test): the follower on its own host
#   formation  test/ros/formation.test with N followers (default 3), each on its own host
#   --log DIR  keep the hosts' logs there (default: a temporary directory, removed on exit)
# e.g. test/multihost/hosts.sh build pair --clocks +2s sim_time:=false \
#        clock_skew_policy:=estimate plant_clock_skew_policy:=estimate
set -eo pipefail
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

tag=pca$$
world=${tag}w
skip() { echo "skipped: $*"; exit 77; }
[ "$(id -u)" = 0 ] || skip "not root: network namespaces need CAP_SYS_ADMIN"
command -v ip >/dev/null || skip "no ip command (iproute2)"
hosts=("$world")
for i in $(seq "$followers"); do hosts+=("${tag}f$i"); done
log=${keep_log:-$(mktemp -d)}
mkdir -p "$log"
cleanup() {
  for ns in "${hosts[@]}"; do
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -INT 2>/dev/null || true
  done
  sleep 2
  for ns in "${hosts[@]}"; do
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -KILL 2>/dev/null || true
    ip netns del "$ns" 2>/dev/null || true
  done
  [[ -n $keep_log ]] || rm -rf "$log"
}
trap cleanup EXIT
ip netns add "$world" 2>/dev/null || skip "ip netns add refused here"
ip -n "$world" link set lo up
ip -n "$world" link add br0 type bridge 2>/dev/null || skip "no bridge links here"
ip -n "$world" addr add 10.231.0.1/24 dev br0
ip -n "$world" link set br0 up
for i in $(seq "$followers"); do
  ns=${tag}f$i
  ip netns add "$ns"
  ip link add "${tag}a$i" type veth peer name "${tag}b$i"
  ip link set "${tag}a$i" netns "$world"
  ip link set "${tag}b$i" netns "$ns"
  ip -n "$world" link set "${tag}a$i" master br0 up
  ip -n "$ns" addr add "10.231.0.$((1 + i))/24" dev "${tag}b$i"
  ip -n "$ns" link set lo up
  ip -n "$ns" link set "${tag}b$i" up
done

# shellcheck disable=SC1091
source "$build/devel/setup.bash"
master=http://10.231.0.1:11311
on_host() {  # on_host NAMESPACE ADDRESS command...
  local ns=$1 address=$2
  shift 2
  ip netns exec "$ns" env ROS_IP="$address" ROS_MASTER_URI=$master ROS_LOG_DIR="$log/ros" "$@"
}
on_host "$world" 10.231.0.1 roscore -p 11311 >"$log/roscore.log" 2>&1 &
for _ in $(seq 100); do
  on_host "$world" 10.231.0.1 rosparam list >/dev/null 2>&1 && break
  sleep 0.1
done
scenario_dir=$(rospack find projection_collision_avoidance)/config/scenarios
for i in $(seq "$followers"); do
  offset=${offsets[$((i - 1))]:-}
  prefix=()
  [[ -n $offset && $offset != 0 ]] && prefix=(faketime -f "$offset")
  if [[ $kind == pair ]]; then
    launch=(pair.launch scenario:="$scenario_dir/paper_run2.yaml" world:=false control_rate:=100)
  else
    launch=(formation.launch scenario:="$scenario_dir/paper_run2.yaml" world:=false
      only_follower:="$i" followers:="$followers" topology:=chain shape:=line control_rate:=100)
  fi
  echo "follower host $i: 10.231.0.$((1 + i)), clock offset ${offset:-0}"
  on_host "${tag}f$i" "10.231.0.$((1 + i))" "${prefix[@]}" roslaunch --wait \
    projection_collision_avoidance "${launch[@]}" "$@" >"$log/follower_$i.log" 2>&1 &
done
# The followers listen before the plant starts (on wall time it does not wait for them).
for _ in $(seq 300); do
  n=$(on_host "$world" 10.231.0.1 rosnode list 2>/dev/null | grep -c controller || true)
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
on_host "$world" 10.231.0.1 rostest --text --reuse-master projection_collision_avoidance "$test_file" \
  "${test_args[@]}" "$@" || {
  for i in $(seq "$followers"); do tail -20 "$log/follower_$i.log"; done
  exit 1
}
