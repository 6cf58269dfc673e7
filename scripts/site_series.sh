#!/usr/bin/env bash
# A site patrolled N times: simulates N flights of one route (objects that appear, move and go between them,
# detections, depth, GPS), maps the first and patrols each later one against the map the previous run wrote,
# with the defaults. Prints per run the map file's size, the peak memory and the wall time (GNU time), and ends
# with eval's site-object line over all of them.
#   scripts/site_series.sh BIN_DIR OUT [FLIGHTS] [SEED] [ROUTE]
set -euo pipefail
bin=$1/patrolmap
out=$2
flights=${3:-10}
seed=${4:-31}
route=${5:-l-shape}
mkdir -p "$out"
if [[ ! -d "$out/logs/flight_$flights" ]]; then  # the logs of an earlier run are flown again
  "$bin" simulate --route "$route" --flights "$flights" --seed "$seed" --objects 20 --detections --depth --gps \
    --out "$out/logs" >/dev/null 2>&1
fi
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
for i in $(seq "$flights" -1 1); do logs+=(--log "$out/logs/flight_$i"); done
"$bin" eval "$out/run_$flights" "${logs[@]}" | grep -E "site objects" || true
# The same flight (the last) patrolled against maps of 1, half and all but one earlier patrols: what a patrol costs
# as the map's history grows, with the flight's own content held fixed.
for prior in 1 $((flights / 2)) $((flights - 1)); do
  measure "last_after_$prior" "$bin" patrol "$out/logs/flight_$flights" --map "$out/run_$prior/map.pmap" \
    --out "$out/last_after_$prior"
done
