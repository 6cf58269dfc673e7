#!/usr/bin/env bash
# Change detection on simulated patrol series (BENCHMARKS.md, "Change detection"): for each route and seed,
# flies a series of 3 flights with objects added, removed and moved between them (and one series that changes
# only the lighting), maps flight 1, adds flights 2 and 3 with `patrol`, and scores every change report with
# `eval`. Prints one line per patrol and writes OUT/summary.json.
# Usage: scripts/change_study.sh [OUT] [PATROLMAP]   (defaults: out/change_study, build/tools/patrolmap)
# Environment: ROUTES, SEEDS (or SERIES="route:seed ..."), OBJECTS (30) choose the series; REUSE_LOGS=1 keeps logs simulated before;
# STEREO=BASELINE_M also renders the right camera (cam1/); DEPTH (auto) sets depth.source: stereo or images;
# STEREO_KEYS="KEY=VALUE ..." sets depth.stereo options and FLIGHT_KEYS depth.flight's (DEPTH=flight: depth from the
# flight's own frames, depth0/ left unread); LIGHTING=0 leaves out the lighting-only series (inner-loop
# seed 1 unless LIGHTING_ROUTE and LIGHTING_SEED say otherwise);
# NO_DETECTOR=1 maps without the detections (objects0/ moved aside; the truth still counts them), so the objects
# scored are the class-agnostic ones from changed geometry; RESOLUTION (376x240) and SCALE (1.0) the images;
# EXTRA_CONFIG=FILE appends FILE's keys (not flow: or depth:) to the study's configuration; POSES=gps maps with
# camera poses from GPS and the IMU's attitude (state_groundtruth_estimate0/ moved aside while mapping; GPS_NOISE,
# GPS_BIAS and ATTITUDE_NOISE set the simulator's noise, the origin lies on the grid so eval scores in the same frame;
# GPS_FIRST=2 leaves flight 1 its state estimate).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/change_study}
pm=${2:-build/tools/patrolmap}
routes=${ROUTES:-"inner-loop l-shape"}
seeds=${SEEDS:-"1 2"}
objects=${OBJECTS:-30}
mkdir -p "$out"
: > "$out/lines.jsonl"
# Logs at 376x240 processed at full scale: the same images the default 752x480 log gives the flow and place
# stages after their 0.5 downscale, at a quarter of the rendering time.
config="$out/study.yaml"
printf 'flow:\n  frames:\n    scale: %s\n' "${SCALE:-1.0}" > "$config"
simulate_extra=()
[ -n "${STEREO:-}" ] && simulate_extra+=(--stereo "$STEREO")
if [ "${POSES:-}" = gps ]; then
  simulate_extra+=(--gps --gps-origin 47.4 8.4 0 --gps-noise "${GPS_NOISE:-1.5}" --attitude-noise "${ATTITUDE_NOISE:-0.5}" \
    --gps-bias "${GPS_BIAS:-0}")
fi
hide_state() {  # folder suffix: POSES=gps moves the state estimate aside while mapping, back for eval
  [ "${POSES:-}" = gps ] || return 0
  for flight in "$1"/logs/flight_*; do
    [ "${flight##*_}" -ge "${GPS_FIRST:-1}" ] || continue  # GPS_FIRST=2: flight 1 keeps its state estimate
    [ -d "$flight/state_groundtruth_estimate0$2" ] && mv "$flight/state_groundtruth_estimate0$2" "$flight/state_groundtruth_estimate0$3"
  done
  return 0
}
printf 'depth:\n  source: %s\n' "${DEPTH:-auto}" >> "$config"
if [ -n "${STEREO_KEYS:-}" ]; then  # STEREO_KEYS="edge_radius_px=2 edge_jump_px=2": depth.stereo options
  printf '  stereo:\n' >> "$config"
  for pair in $STEREO_KEYS; do printf '    %s: %s\n' "${pair%%=*}" "${pair#*=}" >> "$config"; done
fi
if [ -n "${FLIGHT_KEYS:-}" ]; then  # FLIGHT_KEYS="baseline_m=2": depth.flight options
  printf '  flight:\n' >> "$config"
  for pair in $FLIGHT_KEYS; do printf '    %s: %s\n' "${pair%%=*}" "${pair#*=}" >> "$config"; done
fi
[ -n "${EXTRA_CONFIG:-}" ] && cat "$EXTRA_CONFIG" >> "$config"  # EXTRA_CONFIG=FILE: more keys (not flow: or depth:)
run_series() {  # name route seed extra-simulate-options...
  local name=$1 route=$2 seed=$3
  shift 3
  local dir="$out/$name"
  if [ -z "${REUSE_LOGS:-}" ] || [ ! -d "$dir/logs/flight_3" ]; then  # REUSE_LOGS=1: keep logs of an earlier run
    rm -rf "$dir"
    "$pm" simulate --route "$route" --seed "$seed" --flights 3 --objects "$objects" --detections --depth \
      --resolution "${RESOLUTION:-376x240}" ${simulate_extra[@]+"${simulate_extra[@]}"} "$@" --out "$dir/logs" \
      >/dev/null 2>&1
  fi
  if [ -n "${NO_DETECTOR:-}" ]; then
    for flight in "$dir"/logs/flight_*; do
      [ -d "$flight/objects0" ] && mv "$flight/objects0" "$flight/objects0.hidden"
    done
  fi
  hide_state "$dir" "" .hidden
  "$pm" map "$dir/logs/flight_1" --out "$dir/run_1" -c "$config" >/dev/null 2>&1
  for n in 2 3; do
    "$pm" patrol "$dir/logs/flight_$n" --map "$dir/run_$((n - 1))/map.pmap" --out "$dir/run_$n" -c "$config" \
      2>/dev/null | tail -1
  done
  hide_state "$dir" .hidden ""
  for n in 2 3; do
    local logs=(--log "$dir/logs/flight_$n" --log "$dir/logs/flight_$((n - 1))")
    [ "$n" = 3 ] && logs+=(--log "$dir/logs/flight_1")
    "$pm" eval "$dir/run_$n" "${logs[@]}" -c "$config" --json |
      /usr/bin/python3 -c "import json,sys; r=json.load(sys.stdin); r['series']='$name'; r['patrol']=$n; print(json.dumps(r))" \
      >> "$out/lines.jsonl"
  done
}
if [ -n "${SERIES:-}" ]; then  # SERIES="l-shape:41 inner-loop:42": these route-seed pairs instead of ROUTES x SEEDS
  for pair in $SERIES; do
    run_series "${pair%%:*}-${pair##*:}" "${pair%%:*}" "${pair##*:}"
  done
else
  for route in $routes; do
    for seed in $seeds; do
      run_series "$route-$seed" "$route" "$seed"
    done
  done
fi
[ "${LIGHTING:-1}" = 0 ] || run_series "lighting-only" "${LIGHTING_ROUTE:-inner-loop}" "${LIGHTING_SEED:-1}" --remove-fraction 0 --move-fraction 0 --added 0
/usr/bin/python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
lines = [json.loads(l) for l in open(out + "/lines.jsonl")]
total = {}
geo = [0, 0, 0]
geo_near, near_m = 0, 0.5  # false voxels within eval's near_change_m of an object that changed: reported too wide
app = [0, 0, 0, 0]  # regions, on a change, visible changes, found
route = [0, 0, 0, 0, 0, 0, 0, 0]  # changes, on a change, visible, found, frames, compared pairs, and of the visible
                                 # those in a prior frame (objects that left, places left by a move), found
lighting_route = 0  # changes reported on lighting-only patrols
lost_at = {}  # route: per step, the object changes not found whose furthest region it dropped
for r in lines:
    c = r["changes"]
    states = c.get("objects", {})
    row = [f"{r['series']:16s} patrol {r['patrol']}"]
    for s in ("new", "removed", "moved", "persistent"):
        k = states.get(s, {})
        t = total.setdefault(s, [0, 0, 0])
        t[0] += k.get("true_positives", 0); t[1] += k.get("false_positives", 0); t[2] += k.get("false_negatives", 0)
        row.append(f"{s} {k.get('true_positives',0)}/{k.get('false_positives',0)}/{k.get('false_negatives',0)}")
    g = c.get("geometry", {})
    if g:
        geo[0] += g["true_positives"]; geo[1] += g["false_positives"]; geo[2] += g["false_negatives"]
        geo_near += g.get("false_positives_near_change", 0)
        near_m = g.get("near_change_m", near_m)
        row.append(f"voxels P {g['precision']:.2f} R {g['recall']:.2f} IoU {g['iou']:.2f} ({g['regions']} regions)")
    a = c.get("appearance")
    if a:
        app[0] += a["regions"]; app[1] += a["regions_on_change"]; app[2] += a["changes"]; app[3] += a["changes_found"]
        row.append(f"regions {a['regions_on_change']}/{a['regions']} on changes, {a['changes_found']}/{a['changes']} changes found")
    ro = c.get("route")
    if ro:
        for i, k in enumerate(("changes", "changes_on_change", "visible", "found", "frames", "pairs",
                               "visible_in_prior", "found_in_prior")):
            route[i] += ro.get(k, 0)
        if r["series"] == "lighting-only":
            lighting_route += ro["changes"]
        for step, n in ro.get("lost_at", {}).items():
            lost_at[step] = lost_at.get(step, 0) + n
        row.append(f"route {ro['changes_on_change']}/{ro['changes']} on changes, {ro['found']}/{ro['visible']} found, {ro['pairs']}/{ro['frames']} frames")
    row.append(f"places {c['places_changed']}/{c['places_compared']} changed")
    print("  ".join(row))
def prf(tp, fp, fn):
    p = tp / (tp + fp) if tp + fp else 0.0
    r = tp / (tp + fn) if tp + fn else 0.0
    return p, r, (2 * p * r / (p + r) if p + r else 0.0)
summary = {}
print("totals (true/false/missed, precision, recall, F1):")
for s, (tp, fp, fn) in total.items():
    p, r, f = prf(tp, fp, fn)
    summary[s] = {"tp": tp, "fp": fp, "fn": fn, "precision": p, "recall": r, "f1": f}
    print(f"  {s:10s} {tp}/{fp}/{fn}  P {p:.2f} R {r:.2f} F1 {f:.2f}")
p, r, f = prf(*geo)
iou = geo[0] / sum(geo) if sum(geo) else 0.0
summary["voxels"] = {"tp": geo[0], "fp": geo[1], "fn": geo[2], "precision": p, "recall": r, "f1": f, "iou": iou,
                     "fp_near_change": geo_near}
print(f"  voxels     {geo[0]}/{geo[1]}/{geo[2]}  P {p:.2f} R {r:.2f} F1 {f:.2f} IoU {iou:.2f}, {geo_near} of the false within {near_m:g} m of a change")
p = app[1] / app[0] if app[0] else 0.0
r = app[3] / app[2] if app[2] else 0.0
summary["appearance"] = {"regions": app[0], "regions_on_change": app[1], "changes": app[2], "changes_found": app[3],
                         "precision": p, "recall": r}
print(f"  appearance {app[1]}/{app[0]} regions on object changes (P {p:.2f}), {app[3]}/{app[2]} visible changes found (R {r:.2f})")
p = route[1] / route[0] if route[0] else 0.0
r = route[3] / route[2] if route[2] else 0.0
share = route[5] / route[4] if route[4] else 0.0
summary["route"] = {"changes": route[0], "changes_on_change": route[1], "visible": route[2], "found": route[3],
                    "frames": route[4], "pairs": route[5], "precision": p, "recall": r, "compared_share": share,
                    "visible_in_prior": route[6], "found_in_prior": route[7],
                    "lighting_only_changes": lighting_route, "lost_at": lost_at}
print(f"  route      {route[1]}/{route[0]} changes on object changes (P {p:.2f}), {route[3]}/{route[2]} visible changes found (R {r:.2f}), {share:.0%} of the route compared, {lighting_route} changes on lighting-only patrols")
print(f"             of the visible changes in a prior frame (objects that left, places left by a move) {route[7]}/{route[6]} found")
if lost_at:
    print("             not found, lost at: " + ", ".join(f"{k} {v}" for k, v in sorted(lost_at.items())))
json.dump(summary, open(out + "/summary.json", "w"), indent=1)
PY
