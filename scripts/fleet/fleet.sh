#!/usr/bin/env bash
# Maps a fleet of flight logs, one `patrolmap map` per log, then merges the maps with a tree of
# `patrolmap merge` (FANIN maps per merge), on Slurm (a job array per level, each depending on the one
# before), with GNU parallel on one machine, or one after another. Every task is idempotent: run it again
# after a failure and only the missing maps are made. The merged map equals one `patrolmap map` over all the
# logs in the merge order (patrolmap merge --help).
#
#   scripts/fleet/fleet.sh [options] ROOT LOG...
#     --engine E      slurm, parallel or serial (default: slurm when sbatch is found, else parallel when GNU
#                     parallel is, else serial)
#     --fan-in K      maps per merge (default 8)
#     --jobs J        tasks at once with GNU parallel (default: the cores)
#     --config FILE   YAML configuration for map and merge
#     --vocabulary F  vocabulary for map and merge
#     --wait          Slurm: return when the merge is done, with its exit status
#   Environment: PATROLMAP (the program, default patrolmap on PATH), SBATCH_ARGS (more sbatch options, e.g.
#   "--partition=debug --time=02:00:00").
# Writes ROOT/logs.txt, ROOT/maps/N (one map per log), ROOT/merge-L/N (the tree) and ROOT/map, a link to the
# merged map's folder (ROOT/map/map.pmap).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
engine="" fanin=8 jobs=$(nproc) wait=0 options=()
while (($#)); do
  case $1 in
    --engine) engine=$2; shift 2 ;;
    --fan-in) fanin=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --config | --vocabulary) options+=("$1" "$(realpath "$2")"); shift 2 ;;
    --wait) wait=1; shift ;;
    -h | --help) sed -n '2,/^set -e/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "fleet.sh: unknown option $1 (fleet.sh --help)" >&2; exit 2 ;;
    *) break ;;
  esac
done
(($# >= 2)) || { echo "usage: fleet.sh [options] ROOT LOG... (fleet.sh --help)" >&2; exit 2; }
[[ $fanin =~ ^[0-9]+$ ]] && ((fanin >= 2)) || { echo "fleet.sh: --fan-in $fanin: must be an integer >= 2" >&2; exit 2; }
[[ $jobs =~ ^[0-9]+$ ]] && ((jobs >= 1)) || { echo "fleet.sh: --jobs $jobs: must be an integer >= 1" >&2; exit 2; }
if [[ -z $engine ]]; then
  if command -v sbatch > /dev/null; then engine=slurm
  elif command -v parallel > /dev/null; then engine=parallel
  else engine=serial; fi
fi
case $engine in
  slurm) command -v sbatch > /dev/null || { echo "fleet.sh: --engine slurm: sbatch not found (apt-get install slurm-wlm)" >&2; exit 2; } ;;
  parallel) command -v parallel > /dev/null || { echo "fleet.sh: --engine parallel: GNU parallel not found (apt-get install parallel)" >&2; exit 2; } ;;
  serial) ;;
  *) echo "fleet.sh: --engine $engine: one of slurm, parallel, serial" >&2; exit 2 ;;
esac
root=$(realpath -m "$1")
shift
mkdir -p "$root"
for log in "$@"; do
  [[ -e $log ]] || { echo "fleet.sh: $log: no such flight log" >&2; exit 1; }
  realpath "$log"
done > "$root/logs.tmp"
mv "$root/logs.tmp" "$root/logs.txt"
count=$#
export PATROLMAP=${PATROLMAP:-$(command -v patrolmap || echo patrolmap)}
export PATROLMAP_FLEET_DIR=$here

# The tree: level L merges ceil(count(L-1) / FANIN) groups, up to one map.
levels=() below=$count
while :; do
  tasks=$(((below + fanin - 1) / fanin))
  levels+=("$below")
  below=$tasks
  ((tasks > 1)) || break
done
top=${#levels[@]}
ln -sfn "merge-$top/0" "$root/map"

run_parallel() {  # run_parallel TASKS COMMAND...: tasks 0..TASKS-1 through GNU parallel ({} is the index)
  local tasks=$1
  shift
  parallel --will-cite --halt now,fail=1 -j "$jobs" "$@" ::: $(seq 0 $((tasks - 1)))
}

if [[ $engine != slurm ]]; then
  if [[ $engine == parallel ]]; then
    run_parallel "$count" "$here/map_task.sh" "$root/logs.txt" "$root" {} "${options[@]}"
  else
    for ((i = 0; i < count; i++)); do "$here/map_task.sh" "$root/logs.txt" "$root" "$i" "${options[@]}"; done
  fi
  for ((level = 1; level <= top; level++)); do
    below=${levels[level - 1]}
    tasks=$(((below + fanin - 1) / fanin))
    if [[ $engine == parallel ]]; then
      run_parallel "$tasks" "$here/merge_task.sh" "$root" "$level" "$fanin" "$below" {} "${options[@]}"
    else
      for ((i = 0; i < tasks; i++)); do "$here/merge_task.sh" "$root" "$level" "$fanin" "$below" "$i" "${options[@]}"; done
    fi
  done
  echo "fleet: $count logs mapped and merged: $root/map/map.pmap"
  exit 0
fi

# Slurm: one array per level, each after the one below succeeded.
mkdir -p "$root/slurm"
read -r -a extra <<< "${SBATCH_ARGS:-}"
job=$(sbatch --parsable --export=ALL --job-name=patrolmap-map --array="0-$((count - 1))" \
  --output="$root/slurm/map-%a.out" "${extra[@]}" "$here/map_task.sh" "$root/logs.txt" "$root" array "${options[@]}")
echo "fleet: job $job maps $count logs"
for ((level = 1; level <= top; level++)); do
  below=${levels[level - 1]}
  tasks=$(((below + fanin - 1) / fanin))
  last=()
  ((level == top && wait)) && last=(--wait)
  job=$(sbatch --parsable --export=ALL --job-name="patrolmap-merge-$level" --array="0-$((tasks - 1))" \
    --dependency="afterok:${job%%;*}" --kill-on-invalid-dep=yes --output="$root/slurm/merge-$level-%a.out" \
    "${last[@]}" "${extra[@]}" "$here/merge_task.sh" "$root" "$level" "$fanin" "$below" array "${options[@]}")
  echo "fleet: job ${job%%;*} merges level $level ($tasks tasks)"
done
if ((wait)); then
  [[ -f $root/map/map.pmap ]] || { echo "fleet: the merge did not finish: see $root/slurm/*.out" >&2; exit 1; }
  echo "fleet: $count logs mapped and merged: $root/map/map.pmap"
else
  echo "fleet: submitted; the merged map will be $root/map/map.pmap"
fi
