#!/usr/bin/env bash
# Installs what is missing, builds everything and runs the whole test suite; prints each stage's wall time.
set -euo pipefail
cd "$(dirname "$0")/.."
timed() {
  local start=$SECONDS
  "$@"
  printf 'test.sh: %s took %d min %02d s\n' "$1" $(((SECONDS - start) / 60)) $(((SECONDS - start) % 60))
}
timed scripts/install_deps.sh
timed scripts/build.sh
timed ctest --test-dir build --output-on-failure -j "$(nproc)"
# The amd64 package installed with apt-get and run from outside the repository.
timed scripts/install_check.sh
# The arm64 build: NEON kernels, the cross-built programs and their package against amd64 under qemu.
timed scripts/cross_arm64.sh
# The unit tests and the fuzzing corpus again under AddressSanitizer + UndefinedBehaviorSanitizer.
timed scripts/sanitize.sh
