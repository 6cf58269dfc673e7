#!/usr/bin/env bash
# Fleet scale: maps built apart and merged equal one map over all the logs, whatever the grouping and
# order of the merges; the fleet scripts run it with GNU parallel and on a real single-node Slurm cluster
# started on localhost (each skipped with a message where it is not installed); bad merges are named.
# Usage: fleet_test.sh PATROLMAP_BINARY SOURCE_DIR
set -u
bin=$1
source_dir=$2
source "$(dirname "$0")/shell_lib.sh"
fleet=$source_dir/scripts/fleet/fleet.sh
vocabulary=$source_dir/vocab/default.pmvoc
export PATROLMAP=$bin

# Six short flights of one patrol series (20 s each).
"$bin" -q simulate --route l-shape --seed 3 --flights 6 --speed 4 --resolution 376x240 --objects 0 \
  --out "$work/logs" >/dev/null || { echo "FAIL simulate"; exit 1; }
logs=("$work"/logs/flight_{1..6})
# The maps leave out the evidence grids (depth.source none), which makes each 4x faster: what merges and the
# fleet scripts decide does not depend on them. A merge carrying grids is checked at the end.
config=$work/fleet.yaml
printf 'depth:\n  source: none\n' >"$config"
expect "one map over all" 0 "6 logs: 24 nodes, 15 loop closures" -- \
  "$bin" map "${logs[@]}" -c "$config" --vocabulary "$vocabulary" --out "$work/all"
for i in 1 2 3 4 5 6; do
  "$bin" -q map "${logs[$((i - 1))]}" -c "$config" --vocabulary "$vocabulary" --out "$work/m$i" >/dev/null ||
    { echo "FAIL map flight $i"; failures=$((failures + 1)); }
done

same_map() {  # same_map NAME DIR [ONE]: DIR's map, nodes and closures are byte for byte those of ONE (the one map)
  local name=$1 dir=$2 one=${3:-$work/all} file
  for file in map.pmap nodes.csv loop_closures.csv; do
    if ! cmp -s "$one/$file" "$dir/$file"; then
      echo "FAIL $name: $dir/$file differs from $one/$file"
      failures=$((failures + 1))
      return
    fi
  done
  passes=$((passes + 1))
}

merge() { "$bin" -q merge --vocabulary "$vocabulary" "$@" >/dev/null; }
# Associativity: two trees, the maps in other orders, and all at once.
merge "$work/m1/map.pmap" "$work/m4/map.pmap" -o "$work/a14" &&
  merge "$work/m6/map.pmap" "$work/m2/map.pmap" -o "$work/a62" &&
  merge "$work/m5/map.pmap" "$work/m3/map.pmap" -o "$work/a53" &&
  merge "$work/a62/map.pmap" "$work/a14/map.pmap" -o "$work/a1462" &&
  merge "$work/a53/map.pmap" "$work/a1462/map.pmap" -o "$work/A"
same_map "merge ((1 4) (6 2)) (5 3)" "$work/A"
merge "$work/m3/map.pmap" "$work/m2/map.pmap" -o "$work/b32" &&
  merge "$work/m6/map.pmap" "$work/b32/map.pmap" -o "$work/b632" &&
  merge "$work/b632/map.pmap" "$work/m1/map.pmap" -o "$work/b6321" &&
  merge "$work/m5/map.pmap" "$work/m4/map.pmap" "$work/b6321/map.pmap" -o "$work/B"
same_map "merge ((6 (3 2)) 1) 5 4" "$work/B"
merge "$work"/m{6,5,4,3,2,1}/map.pmap -o "$work/C"
same_map "merge 6 5 4 3 2 1" "$work/C"
expect "merge summary" 0 "2 maps merged: 6 flights, 24 nodes, 15 loop closures" -- \
  "$bin" merge "$work/a53/map.pmap" "$work/a1462/map.pmap" --vocabulary "$vocabulary" -o "$work/D"
expect "diff between flights of two maps" 0 "l-shape-3-f2 -> l-shape-3-f5: " -- \
  "$bin" diff "$work/A/map.pmap" --from l-shape-3-f2 --to l-shape-3-f5 -o "$work/diff"
# With their evidence grids (the default depth: from the flight), two flights' maps merged are the map of both.
for i in 1 2; do
  "$bin" -q map "${logs[$((i - 1))]}" --vocabulary "$vocabulary" --out "$work/g$i" >/dev/null
done
"$bin" -q map "${logs[@]:0:2}" --vocabulary "$vocabulary" --out "$work/g12" >/dev/null
merge "$work/g2/map.pmap" "$work/g1/map.pmap" -o "$work/G"
same_map "merge with evidence grids" "$work/G" "$work/g12"
check "the merged map holds both grids" test "$("$bin" info "$work/G/map.pmap" 2>&1 | grep -cE 'evidence grid [0-9]+ voxels')" -eq 2

# Bad merges are named and leave no map.
expect "flight in two maps" 1 "flight l-shape-3-f1 is in both .*/m1/map.pmap and .*/a14/map.pmap: .*--rename-clashes" -- \
  "$bin" merge "$work/m1/map.pmap" "$work/a14/map.pmap" --vocabulary "$vocabulary" -o "$work/clash"
check "no map after a clash" test ! -e "$work/clash/map.pmap"
expect "renamed clash" 0 "renamed .*/a14/map.pmap: l-shape-3-f1 to l-shape-3-f1-2" -- \
  "$bin" merge "$work/m1/map.pmap" "$work/a14/map.pmap" --rename-clashes --vocabulary "$vocabulary" -o "$work/renamed"
expect "missing map" 1 "$work/none.pmap: cannot read map" -- \
  "$bin" merge "$work/m1/map.pmap" "$work/none.pmap" --vocabulary "$vocabulary" -o "$work/missing"
head -c 5000 "$work/m2/map.pmap" >"$work/cut.pmap"
expect "truncated map" 1 "cut.pmap: " -- \
  "$bin" merge "$work/m1/map.pmap" "$work/cut.pmap" --vocabulary "$vocabulary" -o "$work/cut"
"$bin" -q vocab build "$source_dir/flight_logs/sample" -k 4 -L 2 --every 30 --out "$work/small.pmvoc" >/dev/null
expect "another vocabulary" 1 "m1/map.pmap was built with the vocabulary default.pmvoc .* not with .*small.pmvoc" -- \
  "$bin" merge "$work/m1/map.pmap" "$work/m2/map.pmap" --vocabulary "$work/small.pmvoc" -o "$work/vocab"
expect "output over an input" 1 "m1/map.pmap would replace .*m1/map.pmap \(the map\)" -- "$bin" merge "$work/m1/map.pmap" "$work/m2/map.pmap" -o "$work/m1"
expect "fleet bad fan-in" 2 "--fan-in 1: must be an integer >= 2" -- bash "$fleet" --fan-in 1 "$work/f" "${logs[@]}"
expect "fleet missing log" 1 "$work/nothing: no such flight log" -- bash "$fleet" --engine serial "$work/f" "$work/nothing"

# The fleet scripts: six logs, three maps per merge (a tree of two levels); a second run redoes nothing, and
# after a lost map only that one is made again.
fleet_run() { bash "$fleet" --config "$config" --vocabulary "$vocabulary" "$@"; }
run_fleet() {  # run_fleet ENGINE ROOT
  expect "fleet $1" 0 "fleet: 6 logs mapped and merged" -- fleet_run --engine "$1" --wait --fan-in 3 "$2" "${logs[@]}"
  same_map "fleet $1" "$2/map"
}
run_fleet serial "$work/serial"
expect "fleet rerun skips" 0 "map 5: .* complete, skipped" -- \
  fleet_run --engine serial --fan-in 3 "$work/serial" "${logs[@]}"
rm -rf "$work/serial/maps/2" "$work/serial/merge-1" "$work/serial/merge-2"
expect "fleet remakes a lost map" 0 "map 2: .*flight_3 -> " -- \
  fleet_run --engine serial --fan-in 3 "$work/serial" "${logs[@]}"
same_map "fleet after a lost map" "$work/serial/map"
if command -v parallel >/dev/null; then
  run_fleet parallel "$work/parallel"
else
  echo "SKIP fleet with GNU parallel: not installed (apt-get install parallel)"
fi

# A single-node Slurm cluster on localhost, private to this test (its own munge key, ports and state).
start_slurm() {
  local dir=$work/slurm host port
  host=$(hostname)
  port=$((20000 + RANDOM % 20000))
  mkdir -p "$dir"/{state,spool,log}
  chmod 755 "$work" "$dir"  # munged wants its socket's folders open to all
  cat >"$dir/slurm.conf" <<CONF
ClusterName=patrolmap-fleet-test
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=$(id -un)
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge.sock
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=fleet Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  dd if=/dev/urandom of="$dir/munge.key" bs=1024 count=1 2>/dev/null
  chmod 400 "$dir/munge.key"
  export SLURM_CONF=$dir/slurm.conf
  munged --key-file="$dir/munge.key" --socket="$dir/munge.sock" --pid-file="$dir/munged.pid" \
    --log-file="$dir/log/munged.log" --seed-file="$dir/munge.seed" || return 1
  slurmctld -i >>"$dir/log/slurmctld.out" 2>&1 || return 1
  slurmd >>"$dir/log/slurmd.out" 2>&1 || return 1
  for _ in $(seq 1 30); do
    sinfo -h -o %t 2>/dev/null | grep -q idle && return 0
    sleep 1
  done
  return 1
}
stop_slurm() {
  local dir=$work/slurm pid
  for pid in slurmd slurmctld munged; do
    [[ -f $dir/$pid.pid ]] && kill "$(cat "$dir/$pid.pid")" 2>/dev/null
  done
  sleep 1
  rm -rf "$work"
}
if ! command -v sbatch >/dev/null || ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  echo "SKIP fleet on Slurm: slurm-wlm and munge are not installed (apt-get install slurm-wlm munge)"
elif [[ $(id -u) -ne 0 ]]; then
  echo "SKIP fleet on Slurm: starting slurmd needs root"
else
  trap stop_slurm EXIT
  if start_slurm; then
    run_fleet slurm "$work/slurm-fleet"
  else
    echo "FAIL could not start a Slurm cluster on localhost:"
    tail -n 5 "$work"/slurm/log/* 2>/dev/null
    failures=$((failures + 1))
  fi
fi

finish fleet_test
