#!/usr/bin/env bash
# Checks that a built workspace works the way README's workspace route uses it: sourcing its
# setup.bash finds the package, rosrun runs cf_sim and reference_sim.py (with the barrier filter)
# on a scenario from the package's share, every node and the nodelet plugins are found, and the
# demo's launch file resolves.
# Usage: scripts/check_workspace.sh SPACE   (a catkin devel space or a colcon install space)
# Prints one line per check and ends with "workspace checks passed"; exits 1 on the first failure.
set -euo pipefail
space=${1:?usage: check_workspace.sh SPACE}
package=projection_collision_avoidance

fail() { echo "check_workspace: $*" >&2; exit 1; }
test -f "$space/setup.bash" || fail "no $space/setup.bash"
set +u  # the workspace's setup scripts read unset variables
# shellcheck disable=SC1091
source "$space/setup.bash"
set -u

share=$(rospack find "$package") || fail "rospack find $package failed"
echo "rospack find: $share"
summary=$(rosrun "$package" cf_sim "$share/config/scenarios/paper_run2.yaml") ||
  fail "rosrun $package cf_sim failed"
[[ $summary == *min_separation=* ]] || fail "cf_sim printed no summary: $summary"
echo "rosrun cf_sim: $summary"
# The reference with the modules it imports (the barrier filter's), one simulated second.
reference=$(rosrun "$package" reference_sim.py "$share/config/scenarios/paper_run2.yaml" \
  --set controller.tracker.enabled=false --set "controller.safety_filter={rate: 4}" \
  --set simulation.duration=1) || fail "rosrun $package reference_sim.py failed"
[[ $reference == *barrier_ticks=* ]] || fail "reference_sim.py printed no summary: $reference"
echo "rosrun reference_sim.py: $reference"
for node in follower_node leader_node plant_node link_relay; do
  catkin_find --first-only --libexec "$package" "$node" >/dev/null || fail "no $node"
done
echo "nodes: follower_node leader_node plant_node link_relay found"
plugins=$(rospack plugins --attrib=plugin nodelet | grep "^$package ") ||
  fail "the nodelet plugins are not exported"
echo "nodelet plugins: ${plugins#"$package "}"
nodes=$(roslaunch --nodes "$package" demo.launch) || fail "roslaunch cannot resolve demo.launch"
echo "roslaunch demo.launch resolves: $(echo "$nodes" | tr '\n' ' ')"
echo "workspace checks passed"
