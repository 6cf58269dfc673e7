#!/usr/bin/env bash
# Re-scores the patrols of a finished scripts/change_study.sh run with other change options, without
# mapping again: for every patrol, `patrolmap diff` with the study's configuration plus OVERRIDES (a YAML
# file of change.* keys, merged over the study's flow settings), then `patrolmap eval`. Prints totals.
# Usage: scripts/change_rescore.sh STUDY_OUT [OVERRIDES.yaml] [PATROLMAP]
set -euo pipefail
cd "$(dirname "$0")/.."
study=$1
overrides=${2:-}
pm=${3:-build/tools/patrolmap}
config=$(mktemp --suffix=.yaml)
trap 'rm -f "$config"' EXIT
cat "$study/study.yaml" > "$config"
[ -n "$overrides" ] && cat "$overrides" >> "$config"
for dir in "$study"/*/; do
  [ -d "$dir/run_3" ] || continue
  for n in 2 3; do
    "$pm" diff "$dir/run_$n/map.pmap" -c "$config" --out "$dir/run_$n" >/dev/null
    logs=(--log "$dir/logs/flight_$n" --log "$dir/logs/flight_$((n - 1))")
    [ "$n" = 3 ] && logs+=(--log "$dir/logs/flight_1")
    "$pm" eval "$dir/run_$n" "${logs[@]}" -c "$config" --json | /usr/bin/python3 -c "import json,sys; print(json.dumps(json.load(sys.stdin)['changes']))"
  done
done | /usr/bin/python3 -c "
import json, sys
totals = {}
app = [0, 0, 0, 0]
for line in sys.stdin:
    c = json.loads(line)
    a = c.get('appearance')
    if a: app[0] += a['regions']; app[1] += a['regions_on_change']; app[2] += a['changes']; app[3] += a['changes_found']
    for state, k in list(c.get('objects', {}).items()) + [('voxels', c.get('geometry', {}))]:
        if not isinstance(k, dict) or not k: continue
        t = totals.setdefault(state, [0, 0, 0])
        t[0] += k['true_positives']; t[1] += k['false_positives']; t[2] += k['false_negatives']
for state, (tp, fp, fn) in totals.items():
    p = tp / (tp + fp) if tp + fp else 0.0; r = tp / (tp + fn) if tp + fn else 0.0
    print('%-10s %d/%d/%d  P %.3f R %.3f F1 %.3f' % (state, tp, fp, fn, p, r, 2 * p * r / (p + r) if p + r else 0.0))
print('appearance %d/%d regions on object changes, %d/%d visible changes found' % (app[1], app[0], app[3], app[2]))
"
