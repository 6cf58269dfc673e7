#!/usr/bin/env bash
# The main job on the built-in default: installs what is missing, builds, flies the paper's experiment 3
# (the L-shaped path, 82 m) through the simulated village, detects its key locations, scores them against
# the ground truth and writes everything under out/demo/ (override with an argument).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}
scripts/install_deps.sh
scripts/build.sh
rm -rf "$out"
mkdir -p "$out"
build/tools/patrolmap simulate --route l-shape --seed 1 --detections --gps --out "$out/log"
build/tools/patrolmap detect "$out/log" --config config/default.yaml --out "$out/detect"
rsvg-convert -o "$out/detect/response.png" "$out/detect/response.svg"
build/tools/patrolmap eval "$out/detect" --log "$out/log" | tee "$out/eval.txt"
build/tools/patrolmap eval "$out/detect" --log "$out/log" --json > "$out/eval.json"
echo "log: $out/log (ground truth in $out/log/groundtruth/)"
echo "key locations: $out/detect/key_locations.csv, plot: $out/detect/response.svg (and .png)"
