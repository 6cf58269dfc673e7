#!/usr/bin/env bash
# The paper's Tables II and III in the simulated village, three seeds each (BENCHMARKS.md):
#   scripts/sim_study.sh [BIN [VOCABULARY [LOGS [OUT [TABLES]]]]]
# simulates the logs into LOGS once (double loop and L-shape at 90°, inner loop at 45° and 90°), then
# runs `detect` + `eval` per flight (Table II) and `map` + `eval` per experiment (Table III: the double
# loop alone, then the inner loop and the L-shape each mapped after it), and prints one line per run.
# TABLES ("2 3" by default) chooses which tables to run. With CONFIG=FILE in the environment, `map` runs
# with that configuration (for example one that changes a place.* option).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bin="${1:-$root/build/tools/patrolmap}"
vocabulary="${2:-$root/vocab/default.pmvoc}"
logs="${3:-/tmp/patrolmap_sim_logs}"
out="${4:-/tmp/patrolmap_sim_study}"
tables="${5:-2 3}"
config=()
[[ -n "${CONFIG:-}" ]] && config=(--config "$CONFIG")
mkdir -p "$logs" "$out"

simulate() {  # NAME ROUTE MOUNT SEED
  [[ -f "$logs/$1/groundtruth/key_locations.csv" ]] && return
  "$bin" --quiet simulate --route "$2" --mount "$3" --seed "$4" --out "$logs/$1" >/dev/null
}

for seed in 1 2 3; do
  simulate "double-$seed" double-loop 90 "$seed"
  simulate "inner45-$seed" inner-loop 45 "$seed"
  simulate "inner90-$seed" inner-loop 90 "$seed"
  simulate "l-$seed" l-shape 90 "$seed"
done

[[ " $tables " == *" 2 "* ]] && echo "# Table II: key locations (nodes, expected, found, false, missed)"
[[ " $tables " == *" 2 "* ]] && for name in double inner45 l; do
  for seed in 1 2 3; do
    run="$out/detect-$name-$seed"
    "$bin" --quiet detect "$logs/$name-$seed" --out "$run" >/dev/null
    printf '%s-%s ' "$name" "$seed"
    "$bin" --quiet eval "$run" --log "$logs/$name-$seed" | sed -n 3p
  done
done

[[ " $tables " == *" 3 "* ]] || exit 0
echo "# Table III: loop closures (experiment 1: double loop; 2: + inner loop 90°; 3: + L-shape)"
echo "# nodes possible found reported false precision recall"
for seed in 1 2 3; do
  for experiment in 1 2 3; do
    run="$out/map-$experiment-$seed"
    extra=()
    [[ $experiment == 2 ]] && extra=("$logs/inner90-$seed")
    [[ $experiment == 3 ]] && extra=("$logs/l-$seed")
    "$bin" --quiet map "$logs/double-$seed" "${extra[@]}" "${config[@]}" --vocabulary "$vocabulary" --out "$run" >/dev/null
    eval_logs=(--log "$logs/double-$seed")
    [[ ${#extra[@]} -gt 0 ]] && eval_logs+=(--log "${extra[0]}")
    printf 'experiment %s seed %s ' "$experiment" "$seed"
    "$bin" --quiet eval "$run" "${eval_logs[@]}" | grep -A1 "^ nodes  possible" | tail -1
  done
done
