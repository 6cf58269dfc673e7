#!/usr/bin/env bash
# Checks the arm64 build's NEON kernels from any machine: cross-compiles the vocabulary's distance kernels and
# their check (tests/arm64/distance_check.cc) with Debian's aarch64 compiler, statically, and runs it under
# qemu-user. Part of scripts/test.sh; needs crossbuild-essential-arm64 and qemu-user-static (install_deps.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
out=build-arm64
mkdir -p "$out"
# As src/vocab/CMakeLists.txt builds distance.cc: no contraction of multiply and add.
aarch64-linux-gnu-g++ -std=c++17 -O2 -ffp-contract=off -static -Iinclude -Itests -I/usr/include/opencv4 \
  src/vocab/distance.cc tests/arm64/distance_check.cc -o "$out/distance_check"
qemu-aarch64-static "$out/distance_check"
