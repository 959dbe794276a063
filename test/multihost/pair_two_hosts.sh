#!/usr/bin/env bash
# The paper's Run 2 across two hosts made of network namespaces: the master, the plant, the leader
# and the test on "world" (10.231.0.1), the follower on "follower" (10.231.0.2), joined by a veth
# pair; each host with its own ROS_IP. FOLLOWER_PREFIX runs the follower under a command (e.g.
# "faketime -f +2s"). Needs root; without the right to make namespaces it says "skipped: why" and
# exits 77. Everything it makes is removed on exit, also on failure.
# Usage: test/multihost/pair_two_hosts.sh BUILD_DIR [launch args for both hosts...]
#   e.g. sim_time:=false clock_skew_policy:=estimate (with FOLLOWER_PREFIX="faketime -f +2s")
set -eo pipefail
build=${1:?build dir}; shift
tag=pca$$
world=${tag}w
follower=${tag}f
skip() { echo "skipped: $*"; exit 77; }
[ "$(id -u)" = 0 ] || skip "not root: network namespaces need CAP_SYS_ADMIN"
command -v ip >/dev/null || skip "no ip command (iproute2)"
cleanup() {
  for ns in "$world" "$follower"; do
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -INT 2>/dev/null || true
  done
  sleep 2
  for ns in "$world" "$follower"; do
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -KILL 2>/dev/null || true
    ip netns del "$ns" 2>/dev/null || true
  done
}
trap cleanup EXIT
ip netns add "$world" 2>/dev/null || skip "ip netns add refused here"
ip netns add "$follower"
ip link add "${tag}a" type veth peer name "${tag}b"
ip link set "${tag}a" netns "$world"
ip link set "${tag}b" netns "$follower"
ip -n "$world" addr add 10.231.0.1/24 dev "${tag}a"
ip -n "$follower" addr add 10.231.0.2/24 dev "${tag}b"
for ns in "$world" "$follower"; do
  ip -n "$ns" link set lo up
done
ip -n "$world" link set "${tag}a" up
ip -n "$follower" link set "${tag}b" up

# shellcheck disable=SC1091
source "$build/devel/setup.bash"
master=http://10.231.0.1:11311
in_world() { ip netns exec "$world" env ROS_IP=10.231.0.1 ROS_MASTER_URI=$master "$@"; }
in_follower() { ip netns exec "$follower" env ROS_IP=10.231.0.2 ROS_MASTER_URI=$master "$@"; }
log=$(mktemp -d)
in_world roscore -p 11311 >"$log/roscore.log" 2>&1 &
for _ in $(seq 100); do
  in_world rosparam list >/dev/null 2>&1 && break
  sleep 0.1
done
scenario=$(rospack find projection_collision_avoidance)/config/scenarios/paper_run2.yaml
in_follower ${FOLLOWER_PREFIX:-} roslaunch --wait projection_collision_avoidance pair.launch \
  scenario:="$scenario" world:=false control_rate:=100 "$@" >"$log/follower.log" 2>&1 &
in_world rostest --reuse-master projection_collision_avoidance paper_run2.test follower:=false "$@" \
  || { tail -30 "$log/follower.log"; exit 1; }
