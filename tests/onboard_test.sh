#!/usr/bin/env bash
# patrolmap-onboard: the map of a replayed log equals patrolmap map's, SIGTERM flushes a loadable map, bad
# input is named.
# Usage: onboard_test.sh PATROLMAP_ONBOARD PATROLMAP SOURCE_DIR
set -u
onboard=$1
bin=$2
source_dir=$3
source "$(dirname "$0")/shell_lib.sh"
sample="$source_dir/flight_logs/sample"
vocabulary="$source_dir/vocab/default.pmvoc"

"$bin" -q map "$sample" --vocabulary "$vocabulary" --out "$work/offline" >/dev/null
output=$("$onboard" "$sample" --fast --vocabulary "$vocabulary" --out "$work/fast" 2>&1)
check "fast replay runs" grep -qE "421 frames .* 3 key frames \(0 lost from the ring\), 3 nodes" <<<"$output"
check "same nodes as patrolmap map" cmp -s "$work/offline/nodes.csv" "$work/fast/nodes.csv"
check "same key locations" cmp -s "$work/offline/key_locations.csv" "$work/fast/key_locations.csv"
"$onboard" "$sample" --fast --inline --vocabulary "$vocabulary" --out "$work/inline" >/dev/null 2>&1
check "inline places: the same map file" cmp -s "$work/fast/map.pmap" "$work/inline/map.pmap"
check "the map loads" grep -qE "1 flights, 3 nodes" <<<"$("$bin" info "$work/fast/map.pmap" 2>&1)"

# Replayed at its own rate (14 s), stopped after 9 s: the map so far is written and loads.
"$onboard" "$sample" --vocabulary "$vocabulary" --out "$work/stopped" >"$work/stopped.txt" 2>&1 &
pid=$!
sleep 9
kill -TERM "$pid"
wait "$pid"
code=$?
check "SIGTERM exits 0" test "$code" -eq 0
check "SIGTERM says so" grep -q "interrupted: " "$work/stopped.txt"
check "SIGTERM map loads" grep -qE "1 flights, [1-9][0-9]* nodes" <<<"$("$bin" info "$work/stopped/map.pmap" 2>&1)"
frames=$(grep -oE "interrupted: [0-9]+ frames" "$work/stopped.txt" | grep -oE "[0-9]+")
check "paced: about 9 s of a 30 Hz log" test "${frames:-0}" -ge 210 -a "${frames:-999}" -le 330

# A later patrol compares its key frames with an onboard map's as with patrolmap map's: same places, same
# registration, same regions (the onboard map keeps the width its key-frame features were found at).
"$bin" -q simulate --route street --walls 3 --speed 5 --flights 2 --resolution 376x240 --seed 3 --out "$work/series"
"$bin" -q map "$work/series/flight_1" --vocabulary "$vocabulary" --out "$work/offline1"
"$onboard" -q "$work/series/flight_1" --fast --vocabulary "$vocabulary" --out "$work/onboard1" >/dev/null
for prior in offline1 onboard1; do
  "$bin" -q patrol "$work/series/flight_2" --map "$work/$prior/map.pmap" --vocabulary "$vocabulary" \
    --out "$work/patrol_$prior" >/dev/null
done
check "patrol against an onboard map compares places alike" /usr/bin/python3 -c "
import json, sys
a, b = (json.load(open('$work/patrol_' + p + '/changes.json'))['places'] for p in ('offline1', 'onboard1'))
sys.exit(0 if a == b and len(a) >= 1 and all(p['registered'] for p in a) else 1)"

output=$("$onboard" "$work/nothing" --vocabulary "$vocabulary" --out "$work/o" 2>&1)
check "missing log exits 1" test $? -eq 1
check "missing log is named" grep -q "$work/nothing" <<<"$output"
output=$("$onboard" camera:x --vocabulary "$vocabulary" --out "$work/o" 2>&1)
check "bad camera" grep -q "expected camera:N" <<<"$output"
"$onboard" "$sample" --queue 0 --out "$work/o" >/dev/null 2>&1
check "queue 0 refused" test $? -eq 2
head -c 300 "$work/fast/map.pmap" > "$work/cut.pmap"
output=$("$onboard" "$sample" --map "$work/cut.pmap" --vocabulary "$vocabulary" --out "$work/o" 2>&1)
check "truncated prior map named" grep -q "cut.pmap: truncated map" <<<"$output"

finish onboard
