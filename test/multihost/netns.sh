# Hosts made of network namespaces, sourced by test/multihost/hosts.sh and experiments/link/run.sh.
# make_hosts N: host 0 "world" (10.231.0.1) with a bridge, and hosts 1..N (10.231.0.(1+i)), each
# joined to the bridge by a veth pair; a master on world (port 11311). on_host I COMMAND... runs a
# command on host I with its own ROS_IP, the master's URI and ROS_LOG_DIR under $log. The caller
# sets $log (a directory) and $keep_log (non-empty: keep $log) first. Where namespaces cannot be
# made, "skipped: why" and exit 77. Everything made is removed on exit, also on failure.
# shellcheck shell=bash

netns_tag=pca$$
netns_hosts=()
# Cases run side by side: whether /run/netns was a mount point before any of them is kept in a
# marker beside it, read and changed under one lock, so the last one out unmounts what the first
# one in made.
netns_lock=/run/pca-netns.lock
netns_marker=/run/pca-netns.made-mount

netns_skip() {
  echo "skipped: $*"
  exit 77
}

netns_cleanup() {
  for ns in "${netns_hosts[@]}"; do
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -INT 2>/dev/null || true
  done
  # Up to 5 s for them to end on SIGINT, then SIGKILL.
  local _ ns_pids
  for _ in $(seq 50); do
    ns_pids=""
    for ns in "${netns_hosts[@]}"; do
      ns_pids+=$(ip netns pids "$ns" 2>/dev/null || true)
    done
    [[ -z $ns_pids ]] && break
    sleep 0.1
  done
  for ns in "${netns_hosts[@]}"; do
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -KILL 2>/dev/null || true
    ip netns del "$ns" 2>/dev/null || true
  done
  # `ip netns add` made /run/netns a mount point of itself when it was none: the last one out
  # undoes that too.
  (
    flock 9
    if [[ -e $netns_marker ]] && [[ -z $(ip netns list 2>/dev/null) ]]; then
      umount /run/netns 2>/dev/null || true
      rm -f "$netns_marker"
    fi
  ) 9>"$netns_lock"
  [[ -n ${keep_log:-} ]] || rm -rf "$log"
}

# `ip` inside a namespace (not `ip -n`, which remounts / as `ip netns exec` does).
netns_ip() {
  local ns=$1
  shift
  nsenter --net="/run/netns/$ns" ip "$@"
}

host_address() { echo "10.231.0.$((1 + $1))"; }

make_hosts() {
  local n=$1 world=${netns_tag}h0 i ns
  [ "$(id -u)" = 0 ] || netns_skip "not root: network namespaces need CAP_SYS_ADMIN"
  command -v ip >/dev/null || netns_skip "no ip command (iproute2)"
  command -v nsenter >/dev/null || netns_skip "no nsenter command (util-linux)"
  command -v flock >/dev/null || netns_skip "no flock command (util-linux)"
  trap netns_cleanup EXIT
  (
    flock 9
    mountpoint -q /run/netns 2>/dev/null || touch "$netns_marker"
    ip netns add "$world" 2>/dev/null
  ) 9>"$netns_lock" || netns_skip "ip netns add refused here"
  netns_hosts=("$world")
  netns_ip "$world" link set lo up
  netns_ip "$world" link add br0 type bridge 2>/dev/null || netns_skip "no bridge links here"
  netns_ip "$world" addr add "$(host_address 0)/24" dev br0
  netns_ip "$world" link set br0 up
  for i in $(seq "$n"); do
    ns=${netns_tag}h$i
    ip netns add "$ns"
    netns_hosts+=("$ns")
    ip link add "${netns_tag}a$i" type veth peer name "${netns_tag}b$i"
    ip link set "${netns_tag}a$i" netns "$world"
    ip link set "${netns_tag}b$i" netns "$ns"
    netns_ip "$world" link set "${netns_tag}a$i" master br0 up
    netns_ip "$ns" addr add "$(host_address "$i")/24" dev "${netns_tag}b$i"
    netns_ip "$ns" link set lo up
    netns_ip "$ns" link set "${netns_tag}b$i" up
  done
  on_host 0 roscore -p 11311 >"$log/roscore.log" 2>&1 &
  for _ in $(seq 100); do
    on_host 0 rosparam list >/dev/null 2>&1 && return 0
    sleep 0.1
  done
  echo "no master on $(host_address 0)" >&2
  return 1
}

# nsenter enters the network namespace alone: `ip netns exec` also remounts / and /sys in a
# mount namespace of its own, which a chroot (CI's fresh root) refuses.
on_host() {
  local i=$1
  shift
  nsenter --net="/run/netns/${netns_tag}h$i" env ROS_IP="$(host_address "$i")" \
    ROS_MASTER_URI="http://$(host_address 0):11311" ROS_LOG_DIR="$log/ros" "$@"
}
