#!/usr/bin/env bash
# A site patrolled N times: simulates N flights of one route (objects that appear, move and go between them,
# detections, depth, GPS), maps the first and patrols each later one against the map the previous run wrote,
# with the defaults. Prints per run the map file's size, the peak memory and the wall time (GNU time), and ends
# with eval's site-object line over the last three flights.
#   scripts/site_series.sh BIN_DIR OUT [FLIGHTS] [SEED] [ROUTE]
set -euo pipefail
bin=$1/patrolmap
out=$2
flights=${3:-10}
seed=${4:-31}
route=${5:-l-shape}
mkdir -p "$out"
"$bin" simulate --route "$route" --flights "$flights" --seed "$seed" --objects 20 --detections --depth --gps \
  --out "$out/logs" >/dev/null 2>&1
printf '| run | command | map file | peak memory | wall time |\n|---|---|---|---|---|\n'
measure() {  # measure RUN COMMAND...
  local run=$1
  shift
  /usr/bin/time -f '%M %e' -o "$out/$run.time" "$@" >"$out/$run.log" 2>&1
  read -r kb seconds <"$out/$run.time"
  local bytes
  bytes=$(stat -c %s "$out/$run/map.pmap")
  printf '| %s | %s | %.1f MB | %d MB | %.1f s |\n' "$run" "$2" "$(echo "$bytes / 1000000" | bc -l)" \
    $((kb / 1024)) "$seconds"
}
measure run_1 "$bin" map "$out/logs/flight_1" --out "$out/run_1"
for i in $(seq 2 "$flights"); do
  measure "run_$i" "$bin" patrol "$out/logs/flight_$i" --map "$out/run_$((i - 1))/map.pmap" --out "$out/run_$i"
done
logs=()
for i in $(seq "$flights" -1 $((flights > 2 ? flights - 2 : 1))); do logs+=(--log "$out/logs/flight_$i"); done
"$bin" eval "$out/run_$flights" "${logs[@]}" | grep -E "site objects" || true
