#!/usr/bin/env bash
# Mutation testing (no packaged tool does it for C++ here): applies each mutation of a list, one at a time,
# to a scratch copy of the tree, rebuilds, runs the whole test suite and reports whether a test caught it.
#   scripts/mutate.sh [LIST [SCRATCH]]       LIST: tests/mutations.tsv; SCRATCH: /tmp/patrolmap_mutate
# A mutation is "killed" when the suite fails (it stops at the first failing test), "survived" when it passes, "not built" when it does not
# compile (then it proves nothing and should be rewritten). A developer's tool: about 3 minutes a mutation
# on 2 cores, so not a CI step. Prints one line a mutation and the totals.
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
list="${1:-$root/tests/mutations.tsv}"
scratch="${2:-/tmp/patrolmap_mutate}"
rm -rf "$scratch/tree" && mkdir -p "$scratch/tree"
# --touch: fresh modification times, so a build left from an interrupted run recompiles what a mutation changed.
tar -C "$root" --exclude="./build*" --exclude=./out --exclude=./.git -cf - . | tar -C "$scratch/tree" --touch -xf -
cmake -S "$scratch/tree" -B "$scratch/build" -DCMAKE_BUILD_TYPE=Release -DPATROLMAP_BUILD_TESTS=ON \
  -DPATROLMAP_BUILD_BENCHMARKS=OFF >/dev/null || exit 1
cmake --build "$scratch/build" -j "$(nproc)" >/dev/null || { echo "the unmutated tree does not build" >&2; exit 1; }
ctest --test-dir "$scratch/build" -j "$(nproc)" >/dev/null || { echo "the unmutated suite fails" >&2; exit 1; }
# The shared data sits beside the tree, as it does beside the repository.
[[ -e "$scratch/shared" || ! -e "$root/../shared" ]] || ln -s "$root/../shared" "$scratch/shared"

tried=0 killed=0 survived=0 unbuilt=0
while IFS= read -r line; do
  [[ -z "$line" || "$line" == \#* ]] && continue
  # Split at tabs by hand: read with IFS=tab would merge empty fields.
  IFS=$'\x1f' read -r file original mutant what <<<"${line//$'\t'/$'\x1f'}"
  [[ -n "$what" ]] || { echo "malformed line (4 tab-separated fields needed): $line" >&2; continue; }
  tried=$((tried + 1))
  target="$scratch/tree/$file"
  cp "$target" "$scratch/original"
  if ! python3 - "$target" "$original" "$mutant" <<'PY'
import sys
path, original, mutant = sys.argv[1:4]
text = open(path).read()
if text.count(original) != 1:
    sys.exit(f"{path}: the original text occurs {text.count(original)} times, not once")
open(path, "w").write(text.replace(original, mutant))
PY
  then
    echo "not applied  $file: $what"
    unbuilt=$((unbuilt + 1))
    continue
  fi
  if ! cmake --build "$scratch/build" -j "$(nproc)" >/dev/null 2>&1; then
    result="not built"
    unbuilt=$((unbuilt + 1))
  elif ctest --test-dir "$scratch/build" -j "$(nproc)" --timeout 600 --stop-on-failure >"$scratch/ctest.log" 2>&1; then
    result="SURVIVED"
    survived=$((survived + 1))
  else
    result="killed by $(grep -cE '^[[:space:]]+[0-9]+ - .*\((Failed|SEGFAULT|Subprocess aborted|Timeout|Exception)\)' "$scratch/ctest.log") test(s)"
    killed=$((killed + 1))
  fi
  printf '%-26s %s: %s\n' "$result" "$file" "$what"
  cp "$scratch/original" "$target"
done <"$list"
cmake --build "$scratch/build" -j "$(nproc)" >/dev/null 2>&1
echo "mutations: $tried tried, $killed killed, $survived survived, $unbuilt not applied or not built"
