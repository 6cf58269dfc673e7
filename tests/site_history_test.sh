#!/usr/bin/env bash
# A site object's history over seven patrols, against the simulator's truth: in this series (l-shape at 4 m/s,
# seed 28, 30 objects) crate 8 stands from flight 1, is moved 2.3 m at flight 4 and removed at flight 7. Each patrol
# is compared with the map the one before wrote; `history` must show one site object there, first seen at patrol 1,
# moved at patrol 4 from where it stood to where it went, and not seen at patrol 7, and nothing else.
# Usage: site_history_test.sh PATROLMAP_BINARY
set -u
bin=$1
source "$(dirname "$0")/shell_lib.sh"

"$bin" -q simulate --route l-shape --flights 7 --speed 4 --seed 28 --objects 30 --detections --depth \
  --resolution 376x240 --out "$work/logs" >/dev/null || { echo "FAIL simulate"; exit 1; }
check "map flight 1" "$bin" -q map "$work/logs/flight_1" --out "$work/run_1"
for i in 2 3 4 5 6 7; do
  check "patrol $i" "$bin" -q patrol "$work/logs/flight_$i" --map "$work/run_$((i - 1))/map.pmap" --out "$work/run_$i"
done
truth=$work/logs/flight_4/groundtruth/objects.csv
expect "the crate's place" 0 "crate" -- grep '^8,crate' "$truth"
read -r east north < <(awk -F, '$1 == 8 {print $3, $4}' "$truth")
"$bin" history "$work/run_7/map.pmap" --near "$east" "$north" --radius 1.5 --json >"$work/history.json" 2>&1 ||
  { echo "FAIL history"; cat "$work/history.json"; failures=$((failures + 1)); }
check "the crate's history" python3 - "$work/history.json" "$work/logs" <<'PY'
import csv, json, sys
history, logs = json.load(open(sys.argv[1])), sys.argv[2]
def place(flight):  # crate 8's true position in that flight, or None where it is gone
    for row in csv.reader(open(f"{logs}/flight_{flight}/groundtruth/objects.csv")):
        if row[0] == "8": return [float(row[2]), float(row[3])]
def near(a, b): return a is not None and b is not None and ((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2) ** 0.5 < 1.0
objects = history["objects"]
if len(objects) != 1 or objects[0]["label"] != "crate":
    sys.exit(f"wanted one crate near the place, got {[(o['site_object'], o['label']) for o in objects]}")
events = [(e["patrol"], e["what"], e["from"], e["to"]) for e in objects[0]["events"]]
wanted = [(1, "first seen"), (4, "moved"), (7, "not seen")]
if [(p, w) for p, w, _, _ in events] != wanted or place(7) is not None:
    sys.exit(f"wanted {wanted}, got {[(p, w) for p, w, _, _ in events]}")
if not (near(events[0][3], place(1)) and near(events[1][2], place(3)) and near(events[1][3], place(4))
        and near(events[2][2], place(6))):
    sys.exit(f"positions off the truth: {events}")
PY
finish site_history_test
