#!/usr/bin/env bash
# The main job on the built-in default: installs what is missing, builds, flies a simulated patrol of two
# flights along the paper's L-shaped path (experiment 3) through the village, maps them together (key
# locations from optical flow, loop closures by place recognition within and across flights), reports what
# changed between them (appearance, objects, geometry), scores everything against the ground truth and
# writes it under out/demo/ (override with an argument).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}
scripts/install_deps.sh
scripts/build.sh
rm -rf "$out"
mkdir -p "$out"
pm=build/tools/patrolmap
$pm simulate --route l-shape --flights 2 --seed 1 --objects 20 --detections --depth --gps --out "$out/patrol"
# Flight 1 makes the map; flight 2 is a later patrol matched against it without flight 1's log, and its
# change report (changes.json, changes.html) compares it with flight 1.
$pm map "$out/patrol/flight_1" --config config/default.yaml --out "$out/flight_1"
$pm patrol "$out/patrol/flight_2" --map "$out/flight_1/map.pmap" --config config/default.yaml --out "$out/flight_2"
$pm info "$out/flight_2/map.pmap" | tee "$out/map_info.txt"
for flight in 1 2; do rsvg-convert -o "$out/flight_$flight/response.png" "$out/flight_$flight/response.svg"; done
# Key locations are scored against the first --log; loop closures against all of them.
$pm eval "$out/flight_1" --log "$out/patrol/flight_1" | tee "$out/eval_flight_1.txt"
$pm eval "$out/flight_2" --log "$out/patrol/flight_2" --log "$out/patrol/flight_1" | tee "$out/eval_flight_2.txt"
$pm eval "$out/flight_2" --log "$out/patrol/flight_2" --log "$out/patrol/flight_1" --json > "$out/eval_flight_2.json"
echo "logs: $out/patrol/flight_{1,2} (ground truth in groundtruth/ of each)"
echo "maps: $out/flight_1/map.pmap, then extended by the patrol: $out/flight_2/map.pmap (nodes.csv, loop_closures.csv beside)"
echo "changes from flight 1 to flight 2: $out/flight_2/changes.html (and changes.json); scores in $out/eval_flight_2.txt"
