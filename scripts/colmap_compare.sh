#!/usr/bin/env bash
# Runs Debian's COLMAP (SIFT, exhaustive matching, geometric verification; CPU) on the real image sets
# that tests/real_place_test.cc verifies with patrolmap, in a scratch folder, and scores it the same way:
#   scripts/colmap_compare.sh [SCRATCH]
# Needs `apt-get install colmap` and ../shared/data. Prints one line per set (BENCHMARKS.md).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
scratch="${1:-/tmp/patrolmap_colmap}"
shared="$root/../shared/data"
opencv=/usr/share/doc/opencv-doc/examples/data
command -v colmap >/dev/null || { echo "colmap is not installed (apt-get install colmap)" >&2; exit 1; }
rm -rf "$scratch" && mkdir -p "$scratch/pairs" "$scratch/kitti"
for i in 0 1 2 3; do
  cp "$shared/dbow2_demo/image$i.png" "$scratch/pairs/dbow2_$i.png"
  cp "$shared/euroc_revisit_pairs/left_img_$i.png" "$scratch/pairs/euroc_$i.png"
done
for name in graf1.png graf3.png leuvenA.jpg leuvenB.jpg aero1.jpg aero3.jpg; do cp "$opencv/$name" "$scratch/pairs/"; done
cp "$shared"/kitti_seq2/image_l/*.png "$scratch/kitti/"
for set in pairs kitti; do
  colmap feature_extractor --database_path "$scratch/$set.db" --image_path "$scratch/$set" \
    --SiftExtraction.use_gpu 0 >"$scratch/$set.log" 2>&1
  colmap exhaustive_matcher --database_path "$scratch/$set.db" --SiftMatching.use_gpu 0 >>"$scratch/$set.log" 2>&1
done
python3 "$root/scripts/colmap_score.py" "$scratch" "$shared/kitti_seq2/poses.txt"
