#!/usr/bin/env bash
# The main job on the built-in default: installs what is missing, builds, flies a simulated patrol of two
# flights along the paper's L-shaped path (experiment 3) through the village, maps them together (key
# locations from optical flow, loop closures by place recognition within and across flights), scores both
# against the ground truth and writes everything under out/demo/ (override with an argument).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}
scripts/install_deps.sh
scripts/build.sh
rm -rf "$out"
mkdir -p "$out"
pm=build/tools/patrolmap
$pm simulate --route l-shape --flights 2 --seed 1 --detections --gps --out "$out/patrol"
$pm map "$out/patrol/flight_1" "$out/patrol/flight_2" --config config/default.yaml --out "$out/map"
for flight in 1 2; do
  rsvg-convert -o "$out/map/l-shape-1-f$flight/response.png" "$out/map/l-shape-1-f$flight/response.svg"
  $pm eval "$out/map/l-shape-1-f$flight" --log "$out/patrol/flight_$flight" | tee "$out/eval_keylocations_f$flight.txt"
done
$pm eval "$out/map" --log "$out/patrol/flight_1" --log "$out/patrol/flight_2" | tee "$out/eval_loopclosures.txt"
$pm eval "$out/map" --log "$out/patrol/flight_1" --log "$out/patrol/flight_2" --json > "$out/eval_loopclosures.json"
echo "logs: $out/patrol/flight_{1,2} (ground truth in groundtruth/ of each)"
echo "map: $out/map/nodes.csv, $out/map/loop_closures.csv; per flight: $out/map/l-shape-1-f{1,2}/ (key locations, plot)"
