#!/usr/bin/env bash
# A new user's first runs: degenerate frames never abort, two logs are never one flight, options and keys are
# checked with a suggestion, files of the wrong kind and hostile YAML are refused naming the file.
# Usage: first_use_test.sh PATROLMAP_BINARY PATROLMAP_ONBOARD_BINARY SOURCE_DIR
set -u
bin=$1
onboard=$2
source_dir=$3
source "$(dirname "$0")/shell_lib.sh"
sample=$source_dir/flight_logs/sample

# write_png FILE WIDTH HEIGHT VALUE: a grey PNG of one value (Python's standard library; no image tool needed).
write_png() {
  /usr/bin/python3 - "$@" <<'PY'
import struct, sys, zlib
path, width, height, value = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
rows = b"".join(b"\0" + bytes([value]) * width for _ in range(height))
open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0))
                       + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))
PY
}

# An image collection (no times) with a blank frame, a saturated one and a 1-pixel one among real frames.
mkdir -p "$work/collection"
for image in $(ls "$sample/cam0/data" | sed -n '1~10p' | head -30); do cp "$sample/cam0/data/$image" "$work/collection/"; done
write_png "$work/collection/grey.png" 160 102 128
write_png "$work/collection/white.png" 160 102 255
write_png "$work/collection/dot.png" 1 1 0
for bits in 4 8; do
  expect "blank frames in an image collection, $bits-bit descriptors" 0 "1 log: [0-9]+ nodes" -- \
    "$bin" map "$work/collection" --every-frame --set place.descriptor_bits=$bits --out "$work/collection_$bits"
done
expect "blank frames, default mapping" 0 "1 log: " -- "$bin" map "$work/collection" --out "$work/collection_flow"
expect "blank frames, detect" 0 "" -- "$bin" detect "$work/collection" --out "$work/collection_detect"
expect "blank frames, onboard" 0 "" -- "$onboard" "$work/collection" --out "$work/collection_onboard"
expect "a map with featureless nodes loads" 0 "1 flight" -- "$bin" info "$work/collection_4/map.pmap"
expect "the no-timestamp warning names --every-frame" 0 "map --every-frame" -- \
  "$bin" detect "$work/collection" --out "$work/collection_detect"

# Two different logs in folders of one name are two flights; the same log twice is refused.
mkdir -p "$work/day1" "$work/day2"
"$bin" -q simulate --route street --walls 3 --speed 4 --resolution 160x102 --plain-lighting --seed 2 \
  --out "$work/day2/cam" >/dev/null
cp -r "$sample" "$work/day1/cam"
sed -i '/flight_id/d' "$work/day1/cam/meta.yaml" "$work/day2/cam/meta.yaml"
"$bin" -q map "$work/day1/cam" --out "$work/day1_map" >/dev/null
expect "a second log of the same folder name is renamed" 0 "the map already has a flight 'cam' from another log; this one is flight 'cam-2'" -- \
  "$bin" patrol "$work/day2/cam" --map "$work/day1_map/map.pmap" --out "$work/day2_map"
expect "both flights kept, with their logs" 0 "2 flights" -- "$bin" info "$work/day2_map/map.pmap"
expect "info names each flight's log" 0 "read from $work/day2/cam \(content [0-9a-f]{16}\)" -- \
  "$bin" info "$work/day2_map/map.pmap"
expect "the report compares the two" 0 "\"prior\": *\"cam\"|\"prior_flight\": *\"cam\"" -- cat "$work/day2_map/changes.json"
expect "the same log twice is refused" 1 "this log is already in the map as flight 'cam'" -- \
  "$bin" patrol "$work/day1/cam" --map "$work/day1_map/map.pmap" --out "$work/again"
cp -r "$work/day1/cam" "$work/copy_of_day1"
expect "a copy of a mapped log is refused" 1 "already in the map as flight 'cam'" -- \
  "$bin" patrol "$work/copy_of_day1" --map "$work/day1_map/map.pmap" --out "$work/again"
expect "map of one log twice is refused" 1 "already in the map" -- \
  "$bin" map "$work/day1/cam" "$work/day1/cam" --out "$work/twice"
expect "a chosen id that clashes is refused" 1 "--flight-id cam: the map already has a flight of that id" -- \
  "$bin" patrol "$work/day2/cam" --flight-id cam --map "$work/day1_map/map.pmap" --out "$work/again"
expect "a chosen id" 0 "" -- "$bin" patrol "$work/day2/cam" --flight-id tuesday --map "$work/day1_map/map.pmap" \
  --out "$work/tuesday"
expect "the chosen id is the flight's" 0 "flight tuesday" -- "$bin" info "$work/tuesday/map.pmap"
# EuRoC logs keep their data in mav0/: two flights given as .../mav0 are named by the folders above.
mkdir -p "$work/MH_01/mav0" "$work/MH_02/mav0"
cp -r "$work/day1/cam/." "$work/MH_01/mav0/"
cp -r "$work/day2/cam/." "$work/MH_02/mav0/"
"$bin" -q map "$work/MH_01/mav0" --out "$work/mh1" >/dev/null
expect "EuRoC mav0 flights are named by their log" 0 "" -- \
  "$bin" patrol "$work/MH_02/mav0" --map "$work/mh1/map.pmap" --out "$work/mh2"
expect "EuRoC flights MH_01 and MH_02" 0 "flight MH_02 " -- "$bin" info "$work/mh2/map.pmap"
# A flight id never names a folder outside --out.
printf 'flight_id: ../../escaped\n' >>"$work/day1/cam/meta.yaml"
expect "a flight id with a path" 0 "" -- "$bin" map "$work/day1/cam" "$work/day2/cam" --out "$work/contained/out"
check "nothing written outside --out" test ! -e "$work/escaped" -a ! -e "$work/contained/escaped"

# --set and typos.
expect "--set a key" 0 "" -- "$bin" map "$sample" --set place.max_log_nfa=-5 --set flow.smoothing.window_s=0.5 \
  --out "$work/set"
expect "--set an unknown key suggests the nearest" 1 "flow.smothing: unknown key; did you mean 'flow.smoothing" -- \
  "$bin" map "$sample" --set flow.smothing.window_s=1 --out "$work/set"
expect "--set a value of the wrong type" 1 "--set: place.min_inliers: expected an integer, got 'many'" -- \
  "$bin" map "$sample" --set place.min_inliers=many --out "$work/set"
expect "--set out of range" 1 "place.min_inliers = 3: must be an integer in \[8," -- \
  "$bin" map "$sample" --set place.min_inliers=3 --out "$work/set"
expect "--set without a value" 1 "--set place.ratio: expected KEY=VALUE" -- \
  "$bin" map "$sample" --set place.ratio --out "$work/set"
printf 'flow:\n  smothing:\n    window_s: 1\n' >"$work/typo.yaml"
expect "a config key typo suggests the nearest" 1 "typo.yaml:2: flow.smothing: unknown key; did you mean 'flow.smoothing" -- \
  "$bin" map "$sample" --config "$work/typo.yaml" --out "$work/set"
expect "an option typo suggests the nearest" 2 "unknown option '--respnse'; did you mean '--response'" -- \
  "$bin" detect "$sample" --respnse length
expect "patrol --mpa" 2 "unknown option '--mpa'; did you mean '--map'" -- "$bin" patrol --mpa foo x

# Files of the wrong kind, and hostile YAML, are refused naming the file, without library traces.
expect "a map as a log" 1 "map.pmap: a patrolmap map, not a flight log" -- "$bin" map "$work/day1_map/map.pmap" --out "$work/w"
expect "a YAML file as a log" 1 "default.yaml: a text file" -- "$bin" detect "$source_dir/config/default.yaml"
expect "no GStreamer trace" 1 "^error: .*not a flight log" -- "$bin" detect "$work/day1_map/map.pmap"
printf 'a: &a [*a]\n' >"$work/self_alias.yaml"
expect "a YAML self-alias" 1 "self_alias.yaml:1: a YAML alias" -- "$bin" map "$sample" --config "$work/self_alias.yaml" --out "$work/w"
{ echo 'a: &a ["x","x","x","x","x","x","x","x","x","x"]'
  for k in b c d e f g h i j; do echo "$k: &$k [*${prev:-a},*${prev:-a},*${prev:-a},*${prev:-a},*${prev:-a},*${prev:-a},*${prev:-a},*${prev:-a},*${prev:-a},*${prev:-a}]"; prev=$k; done
} >"$work/bomb.yaml"
expect "a YAML alias bomb" 1 "bomb.yaml:2: a YAML alias" -- timeout 20 "$bin" map "$sample" --config "$work/bomb.yaml" --out "$work/w"
cp -r "$sample" "$work/meta_alias"
printf 'a: &a [*a]\n' >"$work/meta_alias/meta.yaml"
expect "a self-alias in meta.yaml" 1 "meta.yaml:1: a YAML alias" -- "$bin" map "$work/meta_alias" --out "$work/w"
printf 'place:\n  ratio: 0.7\n---\nplace:\n  ratio: 0.9\n' >"$work/two.yaml"
expect "a second YAML document" 1 "two.yaml:3: a second YAML document" -- "$bin" map "$sample" --config "$work/two.yaml" --out "$work/w"
python3 -c "print('a:' + ' [' * 200 + ' ]' * 200)" >"$work/deep.yaml"
expect "deep nesting" 1 "deep.yaml:1: maps and lists nested deeper than" -- "$bin" map "$sample" --config "$work/deep.yaml" --out "$work/w"
expect "a folder as --config" 1 "not a regular file" -- "$bin" map "$sample" --config "$work" --out "$work/w"
cp -r "$sample" "$work/fast"
sed -i 's/^frame_rate_hz: .*/frame_rate_hz: 1e308/' "$work/fast/meta.yaml"
expect "a frame rate of 1e308" 1 "meta.yaml: 'frame_rate_hz' must be a frame rate above 0 and at most" -- \
  "$bin" map "$work/fast" --out "$work/w"
mkdir -p "$work/loop"
cp "$sample/cam0/data/"{0,100000000,200000000}.png "$work/loop/" 2>/dev/null
ln -s loop_b "$work/loop/loop_a.png"
ln -s loop_a.png "$work/loop/loop_b"
expect "a symlink loop in an image folder" 0 "" -- "$bin" detect "$work/loop" --out "$work/w"
expect "a huge resolution" 2 "--resolution must look like 752x480, from 32x24 to 8192x8192" -- \
  "$bin" simulate --resolution 100000x100000 --out "$work/w"
expect "an empty --out" 1 "the output folder is empty" -- "$bin" map "$sample" --out ""
expect "patrol with an empty --map" 2 "an empty map name" -- "$bin" patrol "$sample" --map "" --out "$work/w"
cp -r "$sample" "$work/no_table"
rm "$work/no_table/cam0/data.csv"
expect "a EuRoC log without its camera table" 1 "no_table: a EuRoC log without its camera table" -- \
  "$bin" map "$work/no_table" --out "$work/w"
# Inputs are never destroyed by an output.
expect "vocab build over its log" 1 "would replace $work/day1/cam \(the training input\)" -- \
  "$bin" vocab build "$work/day1/cam" --out "$work/day1/cam/cam0/data.csv" -k 4 -L 2
check "the log is untouched" test -s "$work/day1/cam/cam0/data.csv"

finish first_use
