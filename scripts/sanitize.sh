#!/usr/bin/env bash
# Builds patrolmap with AddressSanitizer + UndefinedBehaviorSanitizer into build-sanitize/ and runs the unit
# tests and the fuzzing corpus replays (ctest label "unit") under them. Any finding fails the run: the
# sanitizers stop the program (-fno-sanitize-recover=all) and the test fails. Part of scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DPATROLMAP_SANITIZE=ON -DPATROLMAP_BUILD_TESTS=ON -DPATROLMAP_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-sanitize -j "$(nproc)" --target unit_tests
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1"
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp"
# OpenCV's GStreamer and gphoto2 backends, tried on a file no other backend opens, leak in their own
# libraries (and their frames are not even named): videos are read with FFmpeg here.
export OPENCV_VIDEOIO_PRIORITY_GSTREAMER=0 OPENCV_VIDEOIO_PRIORITY_GPHOTO2=0
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
ctest --test-dir build-sanitize -L unit --output-on-failure -j "$(nproc)"
