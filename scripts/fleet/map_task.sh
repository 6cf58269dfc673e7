#!/usr/bin/env bash
# One task of a fleet run: maps the log on line N (from 0) of LIST into ROOT/maps/N, unless that map is
# complete. The map is built in a scratch folder beside it and renamed into place, so a killed task leaves no
# half map and a rerun redoes only what is missing (idempotent).
#   map_task.sh LIST ROOT N [patrolmap map options...]
# N "array" takes $SLURM_ARRAY_TASK_ID. PATROLMAP names the program (default: patrolmap on PATH).
set -euo pipefail
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
mkdir -p "$root/maps"
scratch=$(mktemp -d "$root/maps/.$index.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
"$patrolmap" -q map "$log" -o "$scratch" "$@"
rm -rf "$out"
chmod 755 "$scratch"
mv "$scratch" "$out"
trap - EXIT
echo "map $index: $log -> $out/map.pmap"
