#!/usr/bin/env bash
# Command-line behaviour: exit codes, messages that name the file, outputs.
# Usage: cli_test.sh PATROLMAP_BINARY SOURCE_DIR
set -u
bin=$1
source_dir=$2
source "$(dirname "$0")/shell_lib.sh"

expect "no subcommand" 2 "subcommand" -- "$bin"
expect "missing log" 1 "$work/nothing: no such file or folder" -- "$bin" detect "$work/nothing" --out "$work/o"
mkdir -p "$work/empty"
expect "empty folder" 1 "folder holds no images" -- "$bin" detect "$work/empty" --out "$work/o"
expect "missing config" 1 "nope.yaml: no such file" -- "$bin" detect "$work/empty" --config "$work/nope.yaml"
printf 'flow:\n  smoothing:\n    windw: 3\n' >"$work/bad.yaml"
expect "unknown config key" 1 "bad.yaml:3: flow.smoothing.windw: unknown key" -- \
  "$bin" detect "$work/empty" --config "$work/bad.yaml"
expect "bad override" 1 "--response must be" -- "$bin" detect "$work/empty" --response speed

expect "simulate" 0 "frames at 30 Hz" -- "$bin" simulate --route street --walls 2 --speed 6 --out "$work/log"
expect "detect" 0 "key locations" -- "$bin" detect "$work/log" --config "$source_dir/config/default.yaml" --out "$work/out"
for file in key_locations.csv response.csv response.svg; do
  [[ -s "$work/out/$file" ]] || { echo "FAIL detect output $file missing"; failures=$((failures + 1)); }
done

# An unreadable image in the middle of the log (frame 20, one the detector decodes) is reported and
# skipped; the run goes on.
middle=$(sed -n '22p' "$work/log/cam0/data.csv" | cut -d, -f2)
echo "garbage" >"$work/log/cam0/data/$middle"
expect "corrupt image" 0 "1 unreadable frames skipped" -- "$bin" detect "$work/log" --out "$work/out2"

# A malformed line in the camera table stops the run with the file and line.
sed -i '7s/^[0-9]*/12x4/' "$work/log/cam0/data.csv"
expect "malformed csv" 1 "cam0/data.csv:7: column 'timestamp \[ns\]': not an integer" -- \
  "$bin" detect "$work/log" --out "$work/out3"

# The committed sample log (flight_logs/sample) still reads, detects and scores: 3 of 3 nodes, none false.
expect "sample detect" 0 "421 frames, 85 processed, 3 key locations" -- \
  "$bin" detect "$source_dir/flight_logs/sample" --out "$work/sample"
expect "sample eval" 0 "street-1 +421 +3 +3 +3 +0 +0" -- "$bin" eval "$work/sample" --log "$source_dir/flight_logs/sample"
expect "eval without outputs" 1 "holds none of key_locations.csv, loop_closures.csv, changes.json" -- \
  "$bin" eval "$work/empty" --log "$source_dir/flight_logs/sample"
expect "unknown route" 2 "unknown route 'zigzag'" -- "$bin" simulate --route zigzag --out "$work/z"

# Place recognition: map the sample with the shipped vocabulary; bad vocabularies are named.
expect "map sample" 0 "1 log: 3 nodes" -- \
  "$bin" map "$source_dir/flight_logs/sample" --vocabulary "$source_dir/vocab/default.pmvoc" --out "$work/map"
[[ -s "$work/map/nodes.csv" && -s "$work/map/loop_closures.csv" ]] || { echo "FAIL map outputs missing"; failures=$((failures + 1)); }
expect "info" 0 "map.pmap: .* KB, 1 flight, 3 nodes, 2 traversals" -- "$bin" info "$work/map/map.pmap"
expect "history without objects" 0 "no site object" -- "$bin" history "$work/map/map.pmap"
expect "history of an unknown flight" 1 "map.pmap: flight 'nope' is not in the map" -- \
  "$bin" history "$work/map/map.pmap" --from nope
# An image folder has no calibration of its own: --camera gives it one (a EuRoC sensor.yaml); a wrong one is named.
printf 'intrinsics: [97.4, 97.4, 79.5, 50.6]\nresolution: [320, 204]\n' >"$work/cam_wrong.yaml"
expect "camera file of another size" 1 "cam_wrong.yaml: resolution 320x204, but .*0.png is 160x102" -- \
  "$bin" map "$source_dir/flight_logs/sample/cam0/data" --fps 10 --camera "$work/cam_wrong.yaml" --out "$work/cammap"
expect "camera file" 0 "1 log: " -- "$bin" map "$source_dir/flight_logs/sample/cam0/data" --fps 10 \
  --camera "$source_dir/flight_logs/sample/cam0/sensor.yaml" --vocabulary "$source_dir/vocab/default.pmvoc" \
  --out "$work/cammap"
printf 'intrinsics: [97.4, 97.4, 79.5, 50.6]\nresolution: [160, 102]\ndistortion_coefficients: [-0.2, 0.05, 0, 0]\n' \
  >"$work/cam_lens.yaml"
"$bin" -q map "$source_dir/flight_logs/sample/cam0/data" --fps 10 --camera "$work/cam_lens.yaml" \
  --vocabulary "$source_dir/vocab/default.pmvoc" --out "$work/lensmap" >/dev/null 2>&1
expect "info names the camera and its lens" 0 "camera 160x102 \(fx 97.4\) through a lens \(k1 -0.2, k2 0.05, p1 0, p2 0\)" \
  -- "$bin" info "$work/lensmap/map.pmap"
"$bin" -q simulate --route street --walls 3 --speed 4 --resolution 160x102 --plain-lighting --seed 2 --out "$work/second" >/dev/null
expect "patrol" 0 "1 log: 3 nodes" -- "$bin" patrol "$work/second" --map "$work/map/map.pmap" \
  --vocabulary "$source_dir/vocab/default.pmvoc" --out "$work/patrol"
expect "patrol extends the map" 0 "2 flights, 6 nodes" -- "$bin" info "$work/patrol/map.pmap"
expect "the map is an SQLite database" 0 "edges +map_info +objects +route_frames" -- \
  sqlite3 "$work/patrol/map.pmap" .tables
# kill -9 at 20 moments of a patrol (fixed seed; half of them in the last fifth, where the map is written): the
# prior map is never touched, and the output is either absent or a whole map of both flights.
prior_sum=$(sha1sum <"$work/map/map.pmap")
started=$(date +%s%N)
"$bin" patrol "$work/second" --map "$work/map/map.pmap" --vocabulary "$source_dir/vocab/default.pmvoc" \
  --out "$work/timed" >/dev/null 2>&1
run_ms=$((($(date +%s%N) - started) / 1000000 + 1))
RANDOM=7
for kill_at in $(seq 1 20); do
  rm -rf "$work/killed"
  delay_ms=$((kill_at % 2 == 0 ? run_ms * 4 / 5 + RANDOM % (run_ms / 5 + 1) : RANDOM % run_ms))
  "$bin" patrol "$work/second" --map "$work/map/map.pmap" --vocabulary "$source_dir/vocab/default.pmvoc" \
    --out "$work/killed" >/dev/null 2>&1 &
  patrol_pid=$!
  sleep "$((delay_ms / 1000)).$(printf '%03d' $((delay_ms % 1000)))"
  kill -9 "$patrol_pid" 2>/dev/null
  wait "$patrol_pid" 2>/dev/null
  [[ $(sha1sum <"$work/map/map.pmap") == "$prior_sum" ]] ||
    { echo "FAIL kill $kill_at (${delay_ms} ms): the prior map changed"; failures=$((failures + 1)); }
  if [[ -e "$work/killed/map.pmap" ]]; then
    expect "kill $kill_at (${delay_ms} ms of ${run_ms}): the output map is whole" 0 "2 flights, 6 nodes" -- \
      "$bin" info "$work/killed/map.pmap"
  fi
done
expect "the prior map after the kills" 0 "1 flight, 3 nodes" -- "$bin" info "$work/map/map.pmap"
# A patrol too short for a key location (30 images, 1 s) is still a flight: its route frames are compared with the
# map's and kept, so the next patrol or `diff` can compare against it.
mkdir -p "$work/short"
for image in $(ls "$source_dir/flight_logs/sample/cam0/data" | sed -n '100,129p'); do
  cp "$source_dir/flight_logs/sample/cam0/data/$image" "$work/short/"
done
expect "patrol without a key location compares its route" 0 "changes street-1 -> short: .*route: 1 of 1 frames compared" \
  -- "$bin" patrol "$work/short" --fps 30 --map "$work/map/map.pmap" --vocabulary "$source_dir/vocab/default.pmvoc" \
  --out "$work/shortpatrol"
expect "info lists the flight without nodes" 0 "flight short +0 nodes, 0.0-0.0 s, 1 frame along the route" -- \
  "$bin" info "$work/shortpatrol/map.pmap"
expect "diff compares the flight without nodes" 0 "street-1 -> short" -- \
  "$bin" diff "$work/shortpatrol/map.pmap" --out "$work/shortdiff"
expect "merge keeps the flight without nodes" 0 "1 map merged: 2 flights, 3 nodes" -- \
  "$bin" merge "$work/shortpatrol/map.pmap" --vocabulary "$source_dir/vocab/default.pmvoc" --out "$work/shortmerge"
head -c 300 "$work/map/map.pmap" > "$work/cut.pmap"
expect "truncated map" 1 "cut.pmap: truncated or damaged" -- "$bin" patrol "$work/second" --map "$work/cut.pmap" \
  --vocabulary "$source_dir/vocab/default.pmvoc" --out "$work/patrol2"
# Exports, read back by real consumers.
expect "export graphml" 0 "" -- "$bin" export "$work/patrol/map.pmap" --format graphml --out "$work/map.graphml"
expect "graphml parses" 0 "" -- xmllint --noout "$work/map.graphml"
expect "graphml nodes" 0 "^6$" -- xmllint --xpath "count(//*[local-name()='node'])" "$work/map.graphml"
"$bin" export "$work/patrol/map.pmap" --format json --out "$work/map.json" >/dev/null
expect "networkx reads graphml and json" 0 "graphml 6 4 json 6 4" -- /usr/bin/python3 -c "
import json, networkx as nx
g = nx.read_graphml('$work/map.graphml')
j = nx.node_link_graph(json.load(open('$work/map.json')))
print('graphml', g.number_of_nodes(), g.number_of_edges(), 'json', j.number_of_nodes(), j.number_of_edges())"
expect "json matches docs/map.schema.json" 0 "valid" -- /usr/bin/python3 -c "
import json, jsonschema
jsonschema.validate(json.load(open('$work/map.json')), json.load(open('$source_dir/docs/map.schema.json')))
print('valid')"
expect "export dot" 0 "" -- "$bin" export "$work/patrol/map.pmap" --format dot --out "$work/map.dot"
expect "dot renders" 0 "<svg" -- dot -Tsvg "$work/map.dot"
expect "export json" 0 "patrolmap.map/1" -- "$bin" export "$work/patrol/map.pmap" --format json
expect "export svg" 0 "" -- "$bin" export "$work/patrol/map.pmap" --format svg --out "$work/map.svg"
expect "svg parses" 0 "" -- xmllint --noout "$work/map.svg"
expect "svg with truth" 0 "missed loop closure" -- "$bin" export "$work/patrol/map.pmap" --format svg \
  --log "$source_dir/flight_logs/sample" --log "$work/second"
expect "svg truth needs every flight" 2 "no --log holds the places" -- "$bin" export "$work/patrol/map.pmap" \
  --format svg --log "$work/second"
expect "export geojson" 0 "FeatureCollection" -- "$bin" export "$work/map/map.pmap" --format geojson
expect "export kml" 0 "" -- "$bin" export "$work/map/map.pmap" --format kml --out "$work/map.kml"
expect "kml parses" 0 "" -- xmllint --noout "$work/map.kml"
"$bin" -q map "$work/second" --vocabulary "$source_dir/vocab/default.pmvoc" --out "$work/nogps" >/dev/null
expect "geojson without gps" 1 "no node has a GPS position" -- "$bin" export "$work/nogps/map.pmap" --format geojson
# The HTML page in headless Chromium: it initialises without a script error and shows node 0's key frame.
expect "export html" 0 "" -- "$bin" export "$work/patrol/map.pmap" --format html --out "$work/map.html"
chrome_profile=$(mktemp -d)
expect "html in chromium" 0 'data-ready="6 nodes, [0-9]+ loop closures?".*node 0 \(street-1.*src="data:image/png;base64,' -- \
  bash -c "timeout 120 chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync --user-data-dir=$chrome_profile \
    --dump-dom file://$work/map.html 2>/dev/null | tr -d '\n'"
rm -rf "$chrome_profile"
expect "export bad format" 2 "format" -- "$bin" export "$work/patrol/map.pmap" --format pdf
expect "foreign map" 1 "not a patrolmap map file" -- "$bin" info "$source_dir/README.md"
expect "missing vocabulary" 1 "nothing.pmvoc: cannot read vocabulary" -- \
  "$bin" map "$source_dir/flight_logs/sample" --vocabulary "$work/nothing.pmvoc" --out "$work/map2"
head -c 1000 "$source_dir/vocab/default.pmvoc" > "$work/cut.pmvoc"
expect "truncated vocabulary" 1 "cut.pmvoc: truncated vocabulary" -- \
  "$bin" map "$source_dir/flight_logs/sample" --vocabulary "$work/cut.pmvoc" --out "$work/map3"
expect "vocab build" 0 "words \(k=4, L=2\)" -- \
  "$bin" vocab build "$source_dir/flight_logs/sample" -k 4 -L 2 --every 30 --out "$work/small.pmvoc"
expect "vocab build bad k" 1 "branching k must be in" -- \
  "$bin" vocab build "$source_dir/flight_logs/sample" -k 1 --out "$work/bad.pmvoc"

# Real use: run from another folder with the shipped vocabulary found beside the binary's sources; a missing
# log is named before anything else; a patrol with another vocabulary names both files.
expect "map from another folder" 0 "1 log: 3 nodes" -- \
  bash -c "cd '$work' && '$bin' map '$source_dir/flight_logs/sample' --out '$work/elsewhere'"
expect "missing log first" 1 "$work/no_log: no such file or folder" -- \
  "$bin" map "$work/no_log" --vocabulary "$work/nothing.pmvoc" --config "$work/nothing.yaml" --out "$work/m4"
expect "vocabulary from the environment" 1 "small.pmvoc \(fingerprint" -- \
  bash -c "PATROLMAP_VOCABULARY='$work/small.pmvoc' '$bin' patrol '$work/second' --map '$work/map/map.pmap' --out '$work/m5'"
expect "patrol with another vocabulary" 1 "map.pmap was built with the vocabulary default.pmvoc .* not with $work/small.pmvoc" -- \
  "$bin" patrol "$work/second" --map "$work/map/map.pmap" --vocabulary "$work/small.pmvoc" --out "$work/patrol3"
# Outputs never destroy inputs; a killed run's temporary is cleaned up by the next one.
cp "$work/map/map.pmap" "$work/keep.pmap"
expect "export over its map" 1 "keep.pmap would replace .*keep.pmap \(the map\)" -- \
  "$bin" export "$work/keep.pmap" --format json --out "$work/./keep.pmap"
check "map untouched by the refused export" cmp -s "$work/map/map.pmap" "$work/keep.pmap"
expect "patrol into the prior's folder" 1 "would replace .*map.pmap \(the prior map\)" -- \
  "$bin" patrol "$work/second" --map "$work/map/map.pmap" --out "$work/map"
check "prior untouched by the refused patrol" cmp -s "$work/map/map.pmap" "$work/keep.pmap"
touch "$work/elsewhere/map.pmap.tmp.999999999"
"$bin" -q map "$source_dir/flight_logs/sample" --out "$work/elsewhere" >/dev/null
check "stale temporary removed" test ! -e "$work/elsewhere/map.pmap.tmp.999999999"
mkdir -p "$work/kitti_like/image_0"
for i in 0 1 2; do cp "$source_dir/flight_logs/sample/cam0/data/"$(ls "$source_dir/flight_logs/sample/cam0/data" | sed -n "$((i + 1))p") \
  "$work/kitti_like/image_0/$(printf %06d $i).png"; done
expect "folder without times warns" 0 "no timestamps, so its frames are taken as 30 Hz; give --fps" -- \
  "$bin" detect "$work/kitti_like/image_0" --out "$work/kl"
printf '0.0\n0.1\n0.2\n' > "$work/kitti_like/times.txt"
expect "times.txt read, short log explained" 0 "lasts 0.2 s, less than twice the smoothing window" -- \
  "$bin" detect "$work/kitti_like/image_0" --out "$work/kl"
expect "bad option names key, value and range" 1 "flow.voting.max_votes = 300: must be an integer in \[3, 100\]" -- \
  bash -c "printf 'flow:\n  voting:\n    max_votes: 300\n' > '$work/votes.yaml' && '$bin' detect '$source_dir/flight_logs/sample' --config '$work/votes.yaml' --out '$work/o'"

finish cli
