#!/usr/bin/env bash
# Installs what is missing, builds everything and runs the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
ctest --test-dir build --output-on-failure -j "$(nproc)"
# The arm64 build's NEON kernels, cross-compiled and run under qemu.
scripts/cross_arm64.sh
# The unit tests and the fuzzing corpus again under AddressSanitizer + UndefinedBehaviorSanitizer.
scripts/sanitize.sh
