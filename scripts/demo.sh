#!/usr/bin/env bash
# The main job on the built-in default: installs what is missing, builds, renders a simulated flight along a
# street with two openings, detects its key locations and writes everything under out/demo/ (override with
# an argument).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}
scripts/install_deps.sh
scripts/build.sh
rm -rf "$out"
mkdir -p "$out"
build/tools/patrolmap simulate --route street --seed 1 --out "$out/log"
build/tools/patrolmap detect "$out/log" --config config/default.yaml --out "$out/detect"
rsvg-convert -o "$out/detect/response.png" "$out/detect/response.svg"
build/tools/patrolmap eval "$out/detect" --log "$out/log"
echo "ground truth: $out/log/groundtruth/key_locations.csv"
echo "plot: $out/detect/response.svg (and .png)"
