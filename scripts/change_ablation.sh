#!/usr/bin/env bash
# Ablation of the change layer's rules (docs/change_rules.md): re-runs the comparison
# of every patrol of finished scripts/change_study.sh runs once per line of ABLATIONS, with that line's keys set
# over the study's configuration (`diff --set`, without mapping again), scores each with `eval`, and prints one
# markdown row per line: object changes, changed voxels, appearance at places and along the route, the fused list
# of entries, and what the lighting-only patrols reported.
# ABLATIONS: one line each, NAME then KEY=VALUE ... (a line with no keys is the baseline; # starts a comment).
# Usage: scripts/change_ablation.sh ABLATIONS OUT STUDY_OUT [STUDY_OUT ...]   (PATROLMAP: build/tools/patrolmap;
# JOBS: ablations run side by side, nproc; ONLY="SERIES ...": those series alone; EVAL_ONLY=1: no `diff`, the
# study's reports scored as they are, so only eval's own comparison (voxels, places, route) sees the keys, at half
# the cost)
set -euo pipefail
cd "$(dirname "$0")/.."
ablations=$1 out=$2
shift 2
pm=$(realpath "${PATROLMAP:-build/tools/patrolmap}")
mkdir -p "$out"
run_ablation() {  # name key=value...: one jsonl line per patrol into OUT/NAME.jsonl
  local name=$1 study dir n
  shift
  local sets=()
  for pair in "$@"; do sets+=(--set "$pair"); done
  : > "$out/$name.jsonl"
  for study in "${studies[@]}"; do
    for dir in "$study"/*/; do
      [ -d "$dir/run_3" ] || continue
      [ -z "${ONLY:-}" ] || [[ " $ONLY " == *" $(basename "$dir") "* ]] || continue
      for n in 2 3; do
        local run="$out/$name/$(basename "$study")/$(basename "$dir")/run_$n"
        mkdir -p "$run"
        ln -sf "$(realpath "$dir/run_$n/map.pmap")" "$run/map.pmap"
        if [ -n "${EVAL_ONLY:-}" ]; then  # the study's report kept: only eval's own comparison sees the keys
          ln -sf "$(realpath "$dir/run_$n/changes.json")" "$run/changes.json"
        else
          "$pm" diff "$run/map.pmap" -c "$study/study.yaml" ${sets[@]+"${sets[@]}"} --out "$run" >/dev/null 2>"$run/diff.log"
        fi
        local logs=(--log "$dir/logs/flight_$n" --log "$dir/logs/flight_$((n - 1))")
        [ "$n" = 3 ] && logs+=(--log "$dir/logs/flight_1")
        "$pm" eval "$run" "${logs[@]}" -c "$study/study.yaml" ${sets[@]+"${sets[@]}"} --json 2>"$run/eval.log" |
          /usr/bin/python3 -c "import json,sys; r=json.load(sys.stdin)['changes']; r['series']=sys.argv[1]; print(json.dumps(r))" \
            "$(basename "$dir")" \
          >> "$out/$name.jsonl"
      done
    done
  done
}
studies=()
for study in "$@"; do studies+=("$(realpath "$study")"); done
export -f run_ablation
export out pm ONLY EVAL_ONLY
export studies_list="${studies[*]}"
grep -v '^\s*\(#\|$\)' "$ablations" | xargs -P "${JOBS:-$(nproc)}" -L 1 bash -c \
  'studies=($studies_list); run_ablation "$@"' _
/usr/bin/python3 - "$ablations" "$out" <<'PY'
import json, sys
names = [l.split()[0] for l in open(sys.argv[1]) if l.strip() and not l.lstrip().startswith("#")]
def ratio(a, b):
    return f"{a / b:.2f}" if b else "-"
def row(name):
    obj, vox, app, route, ent, lighting = [0, 0, 0], [0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0], 0
    for line in open(f"{sys.argv[2]}/{name}.jsonl"):
        c = json.loads(line)
        k = c.get("objects", {}).get("changes", {})
        for i, key in enumerate(("true_positives", "false_positives", "false_negatives")):
            obj[i] += k.get(key, 0)
            vox[i] += c.get("geometry", {}).get(key, 0)
        a = c.get("appearance") or {}
        for i, key in enumerate(("regions", "regions_on_change", "changes", "changes_found")):
            app[i] += a.get(key, 0)
        r = c.get("route") or {}
        for i, key in enumerate(("changes", "changes_on_change", "visible", "found")):
            route[i] += r.get(key, 0)
        e = c.get("entries") or {}
        for i, key in enumerate(("entries", "true_entries", "true_changes", "found")):
            ent[i] += e.get(key, 0)
        if c["series"] == "lighting-only":
            lighting += e.get("entries", 0)
    return (f"| {name} | {obj[0]}/{obj[1]}/{obj[2]} | {ratio(vox[0], vox[0] + vox[1])} {ratio(vox[0], vox[0] + vox[2])} "
            f"| {app[1]}/{app[0]}, {app[3]}/{app[2]} | {route[1]}/{route[0]}, {route[3]}/{route[2]} "
            f"| {ent[1]}/{ent[0]}, {ent[3]}/{ent[2]} | {lighting} |")
print("| ablation | objects true/false/missed | voxels P R | places: on a change / regions, found / visible "
      "| route: same | entries: true / all, found / true changes | lighting-only entries |")
print("|---|---|---|---|---|---|---|")
for name in names:
    print(row(name))
PY
