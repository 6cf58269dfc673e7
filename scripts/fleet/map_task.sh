#!/usr/bin/env bash
# One task of a fleet run: maps the log on line N (from 0) of LIST into ROOT/maps/N, unless that map is
# complete. The map is built in a scratch folder beside it and renamed into place, so a killed task leaves no
# half map and a rerun redoes only what is missing (idempotent).
#   map_task.sh LIST ROOT N [patrolmap map options...]
# N "array" takes $SLURM_ARRAY_TASK_ID. PATROLMAP names the program (default: patrolmap on PATH).
set -euo pipefail
# Slurm runs a copy of this script from its spool folder: fleet.sh says where the scripts are.
source "${PATROLMAP_FLEET_DIR:-$(dirname "$0")}/publish.sh"
list=$1 root=$2
index=$3
[[ $index == array ]] && index=${SLURM_ARRAY_TASK_ID:?map_task.sh: N is array outside a Slurm array task}
shift 3
patrolmap=${PATROLMAP:-patrolmap}
log=$(sed -n "$((index + 1))p" "$list")
[[ -n $log ]] || { echo "map_task.sh: $list has no line $((index + 1))" >&2; exit 1; }
out=$root/maps/$index
if [[ -f $out/map.pmap ]]; then
  echo "map $index: $out/map.pmap is complete, skipped ($log)"
  exit 0
fi
publish "$out" "$patrolmap" -q map "$log" "$@"
echo "map $index: $log -> $out/map.pmap"
