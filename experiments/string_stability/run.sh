#!/usr/bin/env bash
# String stability report: chains and stars of N followers (default 100, FOLLOWERS=N) behind the
# paper's pushed leader (Run 2: config/scenarios/paper_run2.yaml), with the paper's laws and with
# the string-stable configuration of doc/math.md, "Platoons" (config/scenarios/platoon_run2.yaml):
# each topology, tracker off and on, sharing none / same tick / over a link with delay and
# losses, at 100 Hz and 1 kHz. One cf_sim run of N followers gives every shorter chain too (a
# follower does not depend on those behind it).
# Writes to OUT_DIR (default doc/):
#   string_stability.md        the figures per configuration (first follower out of its bound,
#                              inside its perimeter, within 1 mm; peak ratios), per follower
#                              tables, and the error propagation |Gamma| of the analysis
#   string_stability.csv       peak ||xi_i||, bound, min separation and perimeter per follower
#   string_stability.png       peak ||xi_i|| and min separation against i
#   string_stability_gamma.png |Gamma(e^{jwT})| against w (string_stability_analysis.py)
# Usage: experiments/string_stability/run.sh [OUT_DIR]   (about 35 s after the build: 44 cf_sim
#   runs, up to 1 s each, and the analysis). Builds first (BUILD_DIR as for scripts/build.sh),
#   unless CF_SIM=path/to/cf_sim is given.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${1:-$root/doc}
followers=${FOLLOWERS:-100}
# shellcheck source=experiments/common/cf_sim_path.bash
source "$root/experiments/common/cf_sim_path.bash"
find_cf_sim string_stability "$root"
mkdir -p "$out"

paper=config/scenarios/paper_run2.yaml
platoon=config/scenarios/platoon_run2.yaml
info=controller.leader_information
# cf_sim arguments are kept ';'-separated, so that a value may hold spaces.
set_() { printf -- '--set;%s;' "$@"; }
shared=$(set_ "$info.command=true" "$info.disturbance=true")
# A link of LATENCY seconds (or 1 period with "T") losing DROPOUT of the messages, seed 1.
link() {
  local periods=0 latency=$1
  if [[ $1 == T ]]; then periods=1 latency=0; fi
  set_ "$info.link.delay_periods=$periods" "$info.link.latency=$latency" \
    "$info.link.dropout=$2" "$info.link.seed=1"
}
# After the push the leader brakes back to rest (1 m/s^2 for 6 s): the steady reverse speed, and
# with it the headway's steady offset h |v|, is gone, and the peaks measure the transient alone.
stop=$(set_ "leader.input={pulses: [{start: 23.0, end: 29.0, vector: [1.0]}]}")
# group|rate|topology|tracker|sharing|delay|dropout|scenario|cf_sim arguments
runs=()
for rate in 100 1000; do
  for tracker in false true; do
    runs+=("paper|$rate|chain|$tracker|none|-|-|$paper|")
  done
done
for tracker in false true; do
  runs+=("paper|100|chain|$tracker|same tick|0|0|$paper|$shared")
  runs+=("paper|100|star|$tracker|none|-|-|$paper|")
done
for delay in T 0.02 0.1; do
  runs+=("paper|100|chain|true|link|$delay|0|$paper|$shared$(link "$delay" 0)")
done
for tracker in false true; do
  runs+=("paper|100|chain|$tracker|link|0.1|0.2|$paper|$shared$(link 0.1 0.2)")
done
runs+=("paper|1000|chain|true|link|0.1|0.2|$paper|$shared$(link 0.1 0.2)")
runs+=("paper|100|star|true|link|0.1|0.2|$paper|$shared$(link 0.1 0.2)")
runs+=("paper, leader stops|100|chain|true|none|-|-|$paper|$stop")
for rate in 100 1000; do
  runs+=("chosen|$rate|chain|true|same tick|0|0|$platoon|$(set_ "$info.link=null")")
  for delay in T 0.02 0.1; do
    for dropout in 0 0.2; do
      runs+=("chosen|$rate|chain|true|link|$delay|$dropout|$platoon|$(link "$delay" "$dropout")")
    done
  done
  runs+=("chosen|$rate|chain|true|link|0.2|0.2|$platoon|$(link 0.2 0.2)")
done
runs+=("chosen|100|chain|false|link|0.1|0.2|$platoon|$(link 0.1 0.2)")
runs+=("chosen|100|star|true|link|0.1|0.2|$platoon|$(link 0.1 0.2)")
for rate in 100 1000; do
  for delay in 0.1 0.2; do
    arguments=$stop$(link "$delay" 0.2)
    runs+=("chosen, leader stops|$rate|chain|true|link|$delay|0.2|$platoon|$arguments")
  done
done
# The 2-D and 3-D figure eights (the leader loops at up to 2.3 m/s and is pushed back at 2 m/s):
# a line chain and a V chain of each, the paper's laws and the chosen options added by --set.
chosen_options=$(set_ controller.spacing.time_headway=0.3 "$info.command=true" \
  "$info.estimator=true" "$info.disturbance=true" "$info.feedforward.gain=0.7" \
  "$info.feedforward.time_constant=0.2")
for eight in 2d:line 3d:v; do
  file=config/scenarios/figure_eight_${eight%:*}.yaml
  shape=$(set_ "formation.shape=${eight#*:}")
  name="figure eight ${eight%:*}, ${eight#*:}"
  runs+=("paper, $name|100|chain|true|none|-|-|$file|$shape")
  arguments=$shape$chosen_options$(link 0.1 0.2)
  runs+=("chosen, $name|100|chain|true|link|0.1|0.2|$file|$arguments")
done
# The headway alone, nothing shared (ACC): 0.3 s is not enough, 1 s is too much for a reversal.
for headway in 0.3 1.0; do
  headway_only=$(set_ "$info=null" "controller.spacing.time_headway=$headway")
  runs+=("headway $headway s alone|100|chain|true|none|-|-|$platoon|$headway_only")
done

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
manifest=$work/manifest.tsv
printf 'group\trate\ttopology\ttracker\tsharing\tdelay\tdropout\tscenario\targuments\tfile\n' \
  >"$manifest"
start=$(date +%s.%N)
cd "$root"
for i in "${!runs[@]}"; do
  IFS='|' read -r group rate topology tracker sharing delay dropout scenario arguments \
    <<<"${runs[$i]}"
  common=$(set_ "controller.control_rate=$rate" "formation.followers=$followers" \
    "formation.topology=$topology" "formation.shape=line" "controller.tracker.enabled=$tracker")
  # (a later --set formation.shape in the run's own arguments overrides the line)
  IFS=';' read -ra argv <<<"$common$arguments"
  "$CF_SIM" "$scenario" "${argv[@]}" >"$work/$i.txt"
  # The arguments as a shell would take them, for the report.
  quoted=""
  for word in "${argv[@]}"; do
    if [[ $word =~ ^[A-Za-z0-9_.=/:+-]*$ ]]; then quoted+="$word "; else quoted+="'$word' "; fi
  done
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$group" "$rate" "$topology" "$tracker" \
    "$sharing" "$delay" "$dropout" "$scenario" "$quoted" "$work/$i.txt" >>"$manifest"
done
wall=$(/usr/bin/python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.1f}')" \
  "$start" "$(date +%s.%N)")
echo "string_stability: ${#runs[@]} cf_sim runs of $followers followers took $wall s"

/usr/bin/python3 "$here/string_stability_analysis.py" "$platoon" \
  --md "$work/gamma.md" --png "$out/string_stability_gamma.png"
/usr/bin/python3 "$here/plot_string_stability.py" "$manifest" --followers "$followers" \
  --wall "$wall" --gamma "$work/gamma.md" --md "$out/string_stability.md" \
  --csv "$out/string_stability.csv" --png "$out/string_stability.png"
echo "wrote $out/string_stability.md, .csv, .png and string_stability_gamma.png"
