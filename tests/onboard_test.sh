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
check "the map loads" grep -qE "1 flight, 3 nodes" <<<"$("$bin" info "$work/fast/map.pmap" 2>&1)"

# Replayed at its own rate (14 s), stopped after 9 s: the map so far is written and loads.
"$onboard" "$sample" --vocabulary "$vocabulary" --out "$work/stopped" >"$work/stopped.txt" 2>&1 &
pid=$!
sleep 9
kill -TERM "$pid"
wait "$pid"
code=$?
check "SIGTERM exits 0" test "$code" -eq 0
check "SIGTERM says so" grep -q "interrupted: " "$work/stopped.txt"
check "SIGTERM map loads" grep -qE "1 flight, [1-9][0-9]* nodes?" <<<"$("$bin" info "$work/stopped/map.pmap" 2>&1)"
frames=$(grep -oE "interrupted: [0-9]+ frames" "$work/stopped.txt" | grep -oE "[0-9]+")
check "paced: about 9 s of a 30 Hz log" test "${frames:-0}" -ge 210 -a "${frames:-999}" -le 330

# A later patrol compares its route and its key frames with an onboard map's as with patrolmap map's: same
# alignment, same places, same registration, same regions (the onboard map keeps the width its key-frame
# features were found at, and the same route frames).
"$bin" -q simulate --route street --walls 3 --speed 5 --flights 2 --resolution 376x240 --seed 3 --out "$work/series"
"$bin" -q map "$work/series/flight_1" --vocabulary "$vocabulary" --out "$work/offline1"
"$onboard" -q "$work/series/flight_1" --fast --vocabulary "$vocabulary" --out "$work/onboard1" >/dev/null
printf 'change:\n  route:\n    enabled: false\n' > "$work/places.yaml"
for prior in offline1 onboard1; do
  "$bin" -q patrol "$work/series/flight_2" --map "$work/$prior/map.pmap" --vocabulary "$vocabulary" \
    --out "$work/patrol_$prior" >/dev/null
  "$bin" -q diff "$work/patrol_$prior/map.pmap" -c "$work/places.yaml" --out "$work/places_$prior" >/dev/null
done
check "patrol against an onboard map compares the route alike" /usr/bin/python3 -c "
import json, sys
a, b = (json.load(open('$work/patrol_' + p + '/changes.json'))['route'] for p in ('offline1', 'onboard1'))
sys.exit(0 if a == b and a['compared_pairs'] >= 1 else 1)"
check "patrol against an onboard map compares places alike" /usr/bin/python3 -c "
import json, sys
a, b = (json.load(open('$work/places_' + p + '/changes.json'))['places'] for p in ('offline1', 'onboard1'))
sys.exit(0 if a == b and len(a) >= 1 and all(p['registered'] for p in a) else 1)"

# Change detection onboard: on village patrols with detections and depth, the onboard map (objects and grid
# too) is byte for byte the one `patrolmap patrol` writes, on workers or inline, and so is the change report;
# events.jsonl holds whole JSON lines, one per id, and announces every change of the report.
for seed in 1 2; do
  series="$work/village$seed"
  "$bin" -q simulate --route l-shape --speed 4 --flights 2 --detections --depth --resolution 376x240 --seed "$seed" \
    --out "$series"
  "$bin" -q map "$series/flight_1" --vocabulary "$vocabulary" --out "$series/m1"
  "$bin" -q patrol "$series/flight_2" --map "$series/m1/map.pmap" --vocabulary "$vocabulary" --out "$series/p" >/dev/null
  "$onboard" -q "$series/flight_2" --map "$series/m1/map.pmap" --fast --vocabulary "$vocabulary" --out "$series/o" >/dev/null
  "$onboard" -q "$series/flight_2" --map "$series/m1/map.pmap" --fast --inline --vocabulary "$vocabulary" \
    --out "$series/oi" >/dev/null
  check "seed $seed: workers and inline give the same map, objects and grid" cmp -s "$series/o/map.pmap" "$series/oi/map.pmap"
  check "seed $seed: onboard map is patrolmap patrol's" cmp -s "$series/o/map.pmap" "$series/p/map.pmap"
  check "seed $seed: the same change report" /usr/bin/python3 - "$series/p/changes.json" "$series/o/changes.json" <<'PY'
import json, sys
def strip(value):  # timing_s differs from run to run
    if isinstance(value, dict):
        return {k: strip(v) for k, v in value.items() if k != "timing_s"}
    if isinstance(value, list):
        return [strip(v) for v in value]
    return value
a, b = (strip(json.load(open(path))) for path in sys.argv[1:3])
sys.exit(0 if a == b and (a["objects"] or a["geometry"]["regions"]) else 1)
PY
  check "seed $seed: events announce every change of the report" /usr/bin/python3 - "$series/o/events.jsonl" \
    "$series/p/changes.json" <<'PY'
import json, sys
lines = open(sys.argv[1]).read().splitlines()
events = [json.loads(line) for line in lines]
ids = [e["id"] for e in events]
report = json.load(open(sys.argv[2]))
wanted = {o["id"] for o in report["objects"] if o["state"] in ("new", "removed", "moved")}
ok = len(ids) == len(set(ids)) and wanted <= set(ids) and all("time_ns" in e and "confidence" in e for e in events)
# The report's change list under the same ids: every entry is an event, and each final event names its entry.
entries = {c["id"] for c in report["changes"]}
ok = ok and entries <= set(ids) and all(e.get("entry") in entries for e in events if e.get("final"))
sys.exit(0 if ok else 1)
PY
done

# Killed (SIGKILL) at random moments while it writes events: every line present is whole JSON, and the kills
# came while lines were being written (some runs left lines).
lines_left=0
for attempt in 1 2 3 4 5; do
  rm -rf "$work/killed"
  "$onboard" -q "$work/village1/flight_2" --map "$work/village1/m1/map.pmap" --fast --events-interval-s 0.5 \
    --vocabulary "$vocabulary" --out "$work/killed" >/dev/null 2>&1 &
  pid=$!
  sleep "$(/usr/bin/python3 -c "import random; print(round(random.uniform(1.0, 3.0), 2))")"
  kill -KILL "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
  check "SIGKILL $attempt: every event line parses" /usr/bin/python3 -c "
import json, sys
text = open('$work/killed/events.jsonl').read()
[json.loads(line) for line in text.splitlines()]
sys.exit(0 if not text or text.endswith('\n') else 1)"
  lines_left=$((lines_left + $(wc -l <"$work/killed/events.jsonl" 2>/dev/null || echo 0)))
done
check "SIGKILL: the killed runs had written events" test "$lines_left" -gt 0

output=$("$onboard" "$work/nothing" --vocabulary "$vocabulary" --out "$work/o" 2>&1)
check "missing log exits 1" test $? -eq 1
check "missing log is named" grep -q "$work/nothing" <<<"$output"
output=$("$onboard" camera:x --vocabulary "$vocabulary" --out "$work/o" 2>&1)
check "bad camera" grep -q "expected camera:N" <<<"$output"
"$onboard" "$sample" --queue 0 --out "$work/o" >/dev/null 2>&1
check "queue 0 refused" test $? -eq 2
head -c 300 "$work/fast/map.pmap" > "$work/cut.pmap"
output=$("$onboard" "$sample" --map "$work/cut.pmap" --vocabulary "$vocabulary" --out "$work/o" 2>&1)
check "truncated prior map named" grep -q "cut.pmap: truncated or damaged" <<<"$output"

finish onboard
