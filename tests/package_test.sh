#!/usr/bin/env bash
# The Debian packages: `cpack -G DEB` makes patrolmap (the programs, vocabulary and configuration, with the shared
# libraries they need as dependencies) and libpatrolmap-dev (libraries, headers, the CMake package). Unpacked into
# a folder as dpkg would lay them out, the programs run from there and map a log, and tests/downstream builds
# against the development package.
# Usage: package_test.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
source_dir=$2
source "$(dirname "$0")/shell_lib.sh"

(cd "$build" && cpack -G DEB -B "$work/packages" >"$work/cpack.log" 2>&1) ||
  { echo "FAIL cpack:"; tail -5 "$work/cpack.log"; exit 1; }
runtime=$(ls "$work"/packages/patrolmap_*.deb)
development=$(ls "$work"/packages/libpatrolmap-dev_*.deb)
expect "the runtime package needs OpenCV and SQLite" 0 "libopencv-core406.*libsqlite3-0" -- \
  dpkg-deb -f "$runtime" Depends
expect "the development package needs the -dev packages" 0 "libopencv-dev.*libsqlite3-dev" -- \
  dpkg-deb -f "$development" Depends
expect "the runtime package holds both programs and the vocabulary" 0 "usr/share/patrolmap/default.pmvoc" -- \
  dpkg-deb -c "$runtime"
root="$work/root"
dpkg-deb -x "$runtime" "$root" && dpkg-deb -x "$development" "$root"
cd "$work"
expect "the packaged program simulates" 0 "frames at 30 Hz" -- \
  "$root/usr/bin/patrolmap" simulate --route street --walls 2 --speed 6 --out "$work/log"
# It finds a vocabulary by itself (the search tries the packaged one, beside the program, before the source tree).
expect "the packaged program maps" 0 "1 log: [0-9]+ nodes" -- \
  env PATROLMAP_VOCABULARY= "$root/usr/bin/patrolmap" map "$work/log" --out "$work/map"
expect "the packaged onboard program runs" 0 "patrolmap-onboard" -- "$root/usr/bin/patrolmap-onboard" --help
cmake -S "$source_dir/tests/downstream" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$root/usr" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null 2>&1 && cmake --build "$work/consumer" >/dev/null 2>&1
check "tests/downstream builds against the development package" "$work/consumer/consumer"
finish package
