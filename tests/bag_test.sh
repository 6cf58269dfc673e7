#!/usr/bin/env bash
# ROS bags as flight logs: a simulated patrol written as ROS 1 and ROS 2 bags (raw and compressed images,
# plain and compressed chunks) maps to the same nodes and loop closures as its EuRoC logs; every image
# encoding reads; damaged bags, missing topics and mismatched types are named.
# Usage: bag_test.sh PATROLMAP PATROLMAP_ONBOARD SOURCE_DIR
set -u
bin=$1
onboard=$2
source_dir=$3
source "$(dirname "$0")/shell_lib.sh"
python=/usr/bin/python3
writer="$source_dir/tests/write_test_bags.py"
vocabulary="$source_dir/vocab/default.pmvoc"
if ! $python -c "import rosbag, sensor_msgs.msg, nav_msgs.msg, tf2_msgs.msg, cv2, yaml" 2>/dev/null; then
  echo "bag_test: skipped: the bag writer needs python3-rosbag, python3-sensor-msgs, python3-nav-msgs, python3-tf2-msgs,"
  echo "python3-opencv and python3-yaml (scripts/install_deps.sh installs them)"
  finish bag
  exit 0
fi
offset=1700000000  # ROS 1 cannot store time 0, where simulated logs start

# Same nodes and loop closures as the EuRoC logs, after the ROS 1 time offset.
same_map() {  # same_map EUROC_MAP_DIR BAG_MAP_DIR OFFSET_S
  $python - "$1" "$2" "$3" <<'PY'
import csv, sys
a, b, offset = sys.argv[1], sys.argv[2], int(sys.argv[3]) * 10**9
def rows(folder, name, shift):
    table = list(csv.DictReader(open(folder + "/" + name)))
    for row in table:
        row.pop("flight", None)  # a bag is named by its file, a EuRoC log by its meta.yaml
        if "timestamp_ns" in row:
            row["timestamp_ns"] = str(int(row["timestamp_ns"]) - shift)
    return table
nodes, closures = rows(a, "nodes.csv", 0), rows(a, "loop_closures.csv", 0)
ok = nodes == rows(b, "nodes.csv", offset) and closures == rows(b, "loop_closures.csv", offset)
sys.exit(0 if ok and len(nodes) >= 4 and len(closures) >= 1 else 1)
PY
}

"$bin" -q simulate --route street --walls 3 --speed 5 --flights 2 --resolution 376x240 --seed 3 --out "$work/series"
# Nodes and loop closures do not depend on the evidence grids: these maps go without (depth.source none, 3x faster).
nodes_only=$work/nodes_only.yaml
printf 'depth:\n  source: none\n' >"$nodes_only"
"$bin" -q map "$work/series/flight_1" "$work/series/flight_2" -c "$nodes_only" --vocabulary "$vocabulary" \
  --out "$work/euroc" >/dev/null
mkdir -p "$work/bags"
write() {  # write NAME FORMAT ARGS...: both flights as bags NAME/flight_N(.bag)
  local name=$1 format=$2
  shift 2
  mkdir -p "$work/bags/$name"
  for flight in flight_1 flight_2; do
    local out="$work/bags/$name/$flight"
    [[ $format == ros1 ]] && out="$out.bag"
    $python "$writer" "$work/series/$flight" "$out" --format "$format" "$@" || return 1
  done
}
write ros1_raw ros1 --time-offset-s $offset
write ros1_png_bz2 ros1 --images png --chunks bz2 --time-offset-s $offset
write ros1_raw_lz4 ros1 --chunks lz4 --time-offset-s $offset
write ros2_raw ros2
write ros2_png ros2 --images png
for variant in ros1_raw ros1_png_bz2 ros1_raw_lz4 ros2_raw ros2_png; do
  suffix="" shift_s=0
  [[ $variant == ros1* ]] && suffix=".bag" shift_s=$offset
  "$bin" -q map "$work/bags/$variant/flight_1$suffix" "$work/bags/$variant/flight_2$suffix" -c "$nodes_only" \
    --vocabulary "$vocabulary" --out "$work/map_$variant" >/dev/null 2>"$work/map_$variant.err"
  check "$variant: the same nodes and loop closures as the EuRoC logs" same_map "$work/euroc" "$work/map_$variant" $shift_s
done

# JPEG is lossy: the map differs, but the flight maps.
write ros2_jpeg ros2 --images jpeg
expect "JPEG images map" 0 "2 logs: [0-9]+ nodes" -- "$bin" map "$work/bags/ros2_jpeg/flight_1" \
  "$work/bags/ros2_jpeg/flight_2" -c "$nodes_only" --vocabulary "$vocabulary" --out "$work/map_jpeg"

# Every raw encoding gives the grey image mono8 gives: the same key locations.
sample="$source_dir/flight_logs/sample"
"$bin" -q detect "$sample" --out "$work/detect_euroc" >/dev/null
for encoding in mono8 mono16 bgr8 rgb8 bgra8; do
  $python "$writer" "$sample" "$work/enc_$encoding" --format ros2 --encoding "$encoding"
  "$bin" -q detect "$work/enc_$encoding" --out "$work/detect_$encoding" >/dev/null 2>&1
  check "encoding $encoding: the same key locations" cmp -s "$work/detect_euroc/key_locations.csv" \
    "$work/detect_$encoding/key_locations.csv"
done

# Depth for change detection: a depth-image topic gives the evidence grids the EuRoC logs' depth0/ gives, and a
# stereo pair (--topic right=, calibrated from the two CameraInfo) the grids of their cam0/ and cam1/.
"$bin" -q simulate --route street --walls 3 --speed 5 --flights 2 --depth --stereo 0.5 --resolution 376x240 \
  --seed 3 --out "$work/depth" >/dev/null
printf 'depth:\n  source: stereo\n' >"$work/stereo.yaml"
for flight in flight_1 flight_2; do
  $python "$writer" "$work/depth/$flight" "$work/depth/$flight.bag" --format ros1 --chunks lz4 --time-offset-s $offset
done
same_geometry() {  # same_geometry REPORT_A REPORT_B: equal evidence-grid comparisons over some voxels
  $python - "$1" "$2" <<'PY'
import json, sys
a, b = (json.load(open(path))["geometry"] for path in sys.argv[1:3])
for g in (a, b):
    g.pop("timing_s", None)
sys.exit(0 if a == b and a["compared_voxels"] > 1000 else 1)
PY
}
for depth in images stereo; do
  config=() topics=()
  [[ $depth == stereo ]] && config=(--config "$work/stereo.yaml") topics=(--topic right=/cam1/image_raw)
  "$bin" -q map "$work/depth/flight_1" "${config[@]}" --vocabulary "$vocabulary" --out "$work/d_$depth/e1" >/dev/null 2>&1
  "$bin" -q patrol "$work/depth/flight_2" --map "$work/d_$depth/e1/map.pmap" "${config[@]}" --vocabulary "$vocabulary" \
    --out "$work/d_$depth/e2" >/dev/null 2>&1
  "$bin" -q map "$work/depth/flight_1.bag" "${config[@]}" "${topics[@]}" --vocabulary "$vocabulary" \
    --out "$work/d_$depth/b1" >/dev/null 2>&1
  "$bin" -q patrol "$work/depth/flight_2.bag" --map "$work/d_$depth/b1/map.pmap" "${config[@]}" "${topics[@]}" \
    --vocabulary "$vocabulary" --out "$work/d_$depth/b2" >/dev/null 2>&1
  check "depth from $depth in a bag: the EuRoC logs' evidence grids" same_geometry "$work/d_$depth/e2/changes.json" \
    "$work/d_$depth/b2/changes.json"
done
check "the report names stereo depth" grep -q '"current": *"stereo"' "$work/d_stereo/b2/changes.json"

# Topics are listed, and chosen by name.
bag="$work/bags/ros1_raw/flight_1.bag"
expect "info lists a ROS 1 bag's topics" 0 "/imu0 +sensor_msgs/Imu +[0-9]+ msgs +200.00 Hz" -- "$bin" info "$bag"
expect "info lists a ROS 2 bag's topics" 0 "/cam0/image_raw +sensor_msgs/msg/Image +[0-9]+ msgs +30.00 Hz" -- \
  "$bin" info "$work/bags/ros2_raw/flight_1"
expect "--topic chooses the camera" 0 "1 log:" -- "$bin" map "$bag" --topic camera=/cam0/image_raw \
  --topic imu=/imu0 --vocabulary "$vocabulary" --out "$work/chosen"
expect "a topic that does not exist is named, with the bag's topics" 1 "flight_1.bag: no topic /nope .*the bag has .*/cam0/image_raw" -- \
  "$bin" map "$bag" --topic camera=/nope --out "$work/o"
expect "a topic of the wrong type is named" 1 "flight_1.bag, topic /imu0: type sensor_msgs/Imu cannot be the camera topic" -- \
  "$bin" map "$bag" --topic camera=/imu0 --out "$work/o"
expect "an unknown role is refused" 1 "unknown role 'lidar'" -- "$bin" map "$bag" --topic lidar=/x --out "$work/o"
expect "patrolmap-onboard reads a bag" 0 "nodes" -- "$onboard" "$bag" --fast --topic camera=/cam0/image_raw \
  --vocabulary "$vocabulary" --out "$work/onboard_bag"

# Damaged bags: named, never a crash.
size=$(stat -c %s "$bag")
head -c $((size / 2)) "$bag" >"$work/cut.bag"
expect "a truncated ROS 1 bag is named" 1 "cut.bag: .*(truncated|unindexed|reindex)" -- "$bin" map "$work/cut.bag" --out "$work/o"
expect "a truncated ROS 1 bag: info names it" 1 "cut.bag" -- "$bin" info "$work/cut.bag"
cp -r "$work/bags/ros2_raw/flight_1" "$work/cut2"
db="$work/cut2/flight_1_0.db3"
head -c $(($(stat -c %s "$db") / 2)) "$db" >"$db.part" && mv "$db.part" "$db"
expect "a truncated ROS 2 bag is named" 1 "flight_1_0.db3: .*(truncated or damaged|malformed)" -- "$bin" map "$work/cut2" --out "$work/o"
$python - "$work/bags/ros1_raw_lz4/flight_1.bag" "$work/zstd.bag" <<'PY'
import sys
data = open(sys.argv[1], "rb").read()
open(sys.argv[2], "wb").write(data.replace(b"compression=lz4", b"compression=zst"))
PY
expect "an unknown chunk compression is named" 1 "zstd.bag.*(compression|zst)" -- "$bin" map "$work/zstd.bag" --out "$work/o"
cp -r "$work/bags/ros2_raw/flight_1" "$work/mismatch"
$python - "$work/mismatch/flight_1_0.db3" <<'PY'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
db.execute("UPDATE topics SET type = 'sensor_msgs/msg/Image' WHERE name = '/imu0'")
db.commit()
PY
expect "a message that does not hold its type is named" 1 "topic /imu0 \(sensor_msgs/msg/Image\): .*" -- \
  "$bin" map "$work/mismatch" --topic camera=/imu0 --out "$work/o"
cp -r "$work/bags/ros2_raw/flight_1" "$work/mcap"
sed -i 's/storage_identifier: sqlite3/storage_identifier: mcap/' "$work/mcap/metadata.yaml"
expect "another ROS 2 storage is named" 1 "metadata.yaml: storage_identifier 'mcap' is not sqlite3" -- \
  "$bin" map "$work/mcap" --out "$work/o"
cp -r "$work/bags/ros2_raw/flight_1" "$work/zstd2"
$python - "$work/zstd2/metadata.yaml" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
open(sys.argv[1], "w").write(re.sub(r"compression_format: [^\n]*", "compression_format: zstd", text))
PY
expect "a compressed ROS 2 bag is named" 1 "metadata.yaml: compression_format 'zstd'" -- \
  "$bin" map "$work/zstd2" --out "$work/o"
printf 'not a bag' >"$work/junk.bag"
expect "a file that is not a bag is named" 1 "junk.bag" -- "$bin" map "$work/junk.bag" --out "$work/o"

finish bag
