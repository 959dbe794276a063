# Sourced by the scripts that run cf_sim (not run on its own). Sets CF_SIM to the cf_sim to use:
# the one given in CF_SIM, or else the standalone build's (built first by scripts/build.sh into
# BUILD_DIR, default build/). Exits with a message naming the caller if there is none.
#   usage: source "$root/experiments/common/cf_sim_path.bash"; find_cf_sim CALLER ROOT
find_cf_sim() {
  local caller=$1 root=$2
  if [[ -z ${CF_SIM:-} ]]; then
    local build_dir=${BUILD_DIR:-$root/build}
    BUILD_DIR=$build_dir "$root/scripts/build.sh" >/dev/null
    CF_SIM=$build_dir/devel/lib/projection_collision_avoidance/cf_sim
  fi
  test -x "$CF_SIM" || { echo "$caller: no cf_sim at $CF_SIM"; exit 1; }
}
