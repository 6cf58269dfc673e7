#!/usr/bin/env bash
# Mutation testing (no packaged tool does it for C++ here): applies each mutation of a list, one at a time,
# to a scratch copy of the tree, rebuilds, runs the whole test suite and reports whether a test caught it.
#   scripts/mutate.sh [LIST [SCRATCH]]       LIST: tests/mutations.tsv; SCRATCH: /tmp/patrolmap_mutate
# A mutation is "killed" when its stage's test program or else the whole suite fails, "survived" when the
# suite passes, "not built" when it does not compile (then it proves nothing and should be rewritten).
# A developer's tool (a minute or two a mutation on 2 cores, more for survivors), not a CI step. Prints
# one line a mutation and the totals.
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
list="${1:-$root/tests/mutations.tsv}"
scratch="${2:-/tmp/patrolmap_mutate}"
mkdir -p "$scratch/tree"
# Files whose content differs from the repository's (new ones, and one an interrupted run left mutated) are
# copied with a fresh time, so they rebuild; the others keep theirs, so a second run rebuilds little.
(cd "$root" && git ls-files -co --exclude-standard) | while IFS= read -r file; do
  [[ -f "$root/$file" ]] || continue
  cmp -s "$root/$file" "$scratch/tree/$file" && continue
  mkdir -p "$(dirname "$scratch/tree/$file")" && cp "$root/$file" "$scratch/tree/$file"
done
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
  # The test program of the mutated file's stage first (src/STAGE/... -> STAGE_test, built from tests/STAGE/
  # or tests/STAGE_test.cc): seconds, where the whole suite takes minutes. Only a mutation it misses is given
  # the whole suite.
  stage="$(cut -d/ -f2 <<<"$file")"
  stage_test="${stage}_test"
  [[ "$file" == src/* && (-f "$scratch/tree/tests/$stage_test.cc" || -d "$scratch/tree/tests/$stage") ]] || stage_test=""
  if [[ -n "$stage_test" ]] && cmake --build "$scratch/build" -j "$(nproc)" --target "$stage_test" >/dev/null 2>&1 &&
    ! timeout 900 "$scratch/build/tests/$stage_test" --gtest_brief=1 >"$scratch/ctest.log" 2>&1; then
    result="killed by $stage_test"
    killed=$((killed + 1))
  elif ! cmake --build "$scratch/build" -j "$(nproc)" >/dev/null 2>&1; then
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
