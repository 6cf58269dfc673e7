#!/usr/bin/env bash
# Configures and builds patrolmap into build/ (Release, tests and benchmarks on).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPATROLMAP_BUILD_TESTS=ON -DPATROLMAP_BUILD_BENCHMARKS=ON >/dev/null
cmake --build build -j "$(nproc)"
