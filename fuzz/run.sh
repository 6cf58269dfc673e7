#!/usr/bin/env bash
# Builds the libFuzzer harnesses (clang, AddressSanitizer + UndefinedBehaviorSanitizer) into build-fuzz/
# and runs each for SECONDS (default 600), two at a time, starting from the checked-in corpus:
#   fuzz/run.sh [SECONDS [HARNESS...]]     harnesses: map_file vocabulary config euroc image_times pose_file ros_message
# Every input that crashed, hung or ran out of memory is copied into fuzz/corpus/HARNESS/ as
# regression-<hash>, which the test suite replays from then on (after the fix). Prints per harness the
# executions, the coverage (edges) and the findings. Needs clang: sudo apt-get install clang.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-600}"
(($# > 0)) && shift
harnesses=("$@")
((${#harnesses[@]})) || harnesses=(map_file vocabulary config euroc image_times pose_file ros_message)
command -v clang++ >/dev/null || { echo "clang++ not found: sudo apt-get install clang" >&2; exit 1; }
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DPATROLMAP_FUZZ=ON -DPATROLMAP_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-fuzz -j "$(nproc)" --target "${harnesses[@]/%/_fuzzer}" >/dev/null

run_one() {
  local harness="$1" work="build-fuzz/work/$1" artifacts="build-fuzz/artifacts/$1/"
  mkdir -p "$work" "$artifacts"
  ASAN_OPTIONS="detect_leaks=1" UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1" \
    "build-fuzz/fuzz/${harness}_fuzzer" "$work" "fuzz/corpus/$harness" -max_total_time="$seconds" \
    -max_len=65536 -timeout=20 -rss_limit_mb=3072 -artifact_prefix="$artifacts" -print_final_stats=1 \
    >"build-fuzz/$harness.log" 2>&1 || true
}
rm -rf build-fuzz/artifacts  # findings of this run only
pids=()
for harness in "${harnesses[@]}"; do
  run_one "$harness" &
  pids+=($!)
  if ((${#pids[@]} >= $(nproc))); then
    wait "${pids[0]}"
    pids=("${pids[@]:1}")
  fi
done
wait

printf '%-12s %12s %8s %8s %9s\n' harness executions edges features findings
for harness in "${harnesses[@]}"; do
  log="build-fuzz/$harness.log"
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  coverage=$(grep -oE 'cov: [0-9]+ ft: [0-9]+' "$log" | tail -1)
  findings=0
  for artifact in "build-fuzz/artifacts/$harness"/*; do
    [[ -f "$artifact" ]] || continue
    cp "$artifact" "fuzz/corpus/$harness/regression-$(basename "$artifact")"
    findings=$((findings + 1))
  done
  read -r _ edges _ features <<<"${coverage:-cov: ? ft: ?}"
  printf '%-12s %12s %8s %8s %9s\n' "$harness" "${runs:-?}" "$edges" "$features" "$findings"
done
