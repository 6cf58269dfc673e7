#!/usr/bin/env bash
# Installs what is missing, builds everything and runs the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
ctest --test-dir build --output-on-failure -j "$(nproc)"
# The unit tests and the fuzzing corpus again under AddressSanitizer + UndefinedBehaviorSanitizer.
scripts/sanitize.sh
