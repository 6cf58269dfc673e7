#!/usr/bin/env bash
# One task of a fleet run's merge tree: merges maps FANIN*N ... FANIN*N+FANIN-1 of level L-1 (ROOT/maps for
# level 1, ROOT/merge-(L-1) above) into ROOT/merge-L/N, unless that map is complete; built in a scratch folder
# and renamed into place (idempotent, as map_task.sh).
#   merge_task.sh ROOT L FANIN COUNT N [patrolmap merge options...]
# COUNT is the number of maps on level L-1. N "array" takes $SLURM_ARRAY_TASK_ID.
set -euo pipefail
# Slurm runs a copy of this script from its spool folder: fleet.sh says where the scripts are.
source "${PATROLMAP_FLEET_DIR:-$(dirname "$0")}/publish.sh"
root=$1 level=$2 fanin=$3 count=$4
index=$5
[[ $index == array ]] && index=${SLURM_ARRAY_TASK_ID:?merge_task.sh: N is array outside a Slurm array task}
shift 5
patrolmap=${PATROLMAP:-patrolmap}
below=$root/maps
((level > 1)) && below=$root/merge-$((level - 1))
out=$root/merge-$level/$index
if [[ -f $out/map.pmap ]]; then
  echo "merge $level/$index: complete, skipped"
  exit 0
fi
inputs=()
for ((i = index * fanin; i < (index + 1) * fanin && i < count; i++)); do
  [[ -f $below/$i/map.pmap ]] || { echo "merge_task.sh: $below/$i/map.pmap is missing (did its task fail?)" >&2; exit 1; }
  inputs+=("$below/$i/map.pmap")
done
((${#inputs[@]})) || { echo "merge_task.sh: level $level has no task $index" >&2; exit 1; }
publish "$out" "$patrolmap" -q merge "${inputs[@]}" "$@"
echo "merge $level/$index: ${#inputs[@]} maps -> $out/map.pmap"
