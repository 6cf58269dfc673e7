#!/usr/bin/env bash
# The arm64 build, checked from any Debian 12 machine (part of scripts/test.sh):
#  1. the vocabulary's NEON kernels (tests/arm64/distance_check.cc) against the portable loops, under qemu-user;
#  2. an arm64 sysroot of Debian's own packages in build-arm64/sysroot (downloaded once, kept while the package
#     list is unchanged), `patrolmap` and `patrolmap-onboard` cross-built against it;
#  3. a short simulated series through `map`, `patrol` and `patrolmap-onboard --fast` on amd64 and, under qemu,
#     on arm64: nodes, loop closures, objects and changes compared (tests/arm64/compare_runs.py).
# Needs crossbuild-essential-arm64 and qemu-user-static (install_deps.sh) and the amd64 build (scripts/build.sh).
#   scripts/cross_arm64.sh            all three
#   scripts/cross_arm64.sh kernels    only the first
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
out=$root/build-arm64
mkdir -p "$out"
stage() { printf '%s cross_arm64: %s\n' "$(date +%T)" "$*"; }

# 1. The kernels: compiled statically, as src/vocab/CMakeLists.txt builds distance.cc (no contraction).
aarch64-linux-gnu-g++ -std=c++17 -O2 -ffp-contract=off -static -Iinclude -Itests -I/usr/include/opencv4 \
  src/vocab/distance.cc tests/arm64/distance_check.cc -o "$out/distance_check"
qemu-aarch64-static "$out/distance_check"
[[ ${1:-} == kernels ]] && exit 0

# 2. The sysroot: the arm64 -dev packages the build links, with their dependencies, unpacked (dpkg-deb -x) rather
# than installed, because Debian's OpenCV, Ceres and yaml-cpp -dev packages cannot be installed beside their amd64
# versions. ROS 1 bags are left out: librosbag-storage-dev has no arm64 build in Debian 12.
packages=(libc6-dev libstdc++-12-dev libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev
  libopencv-videoio-dev libopencv-video-dev libopencv-features2d-dev libopencv-calib3d-dev libopencv-flann-dev
  libceres-dev libyaml-cpp-dev libspdlog-dev libsqlite3-dev libboost-dev libboost-graph-dev libeigen3-dev
  libcli11-dev nlohmann-json3-dev libnanoflann-dev)
sysroot=$out/sysroot
apt_dir=$out/apt
# The folder is part of the stamp (Ceres's package below names it), and so is the form of .sonames.
want="${packages[*]} libopencv-dev in $sysroot, sonames 1"
if [[ ! -f $sysroot/.packages || $(cat "$sysroot/.packages") != "$want" ]]; then
  stage "setting up the arm64 sysroot in $sysroot"
  rm -rf "$sysroot" "$apt_dir"
  mkdir -p "$apt_dir"/{state/lists/partial,cache/archives/partial,sources,debs} "$sysroot"
  : >"$apt_dir/state/status"
  cp /etc/apt/sources.list.d/*.sources "$apt_dir/sources/" 2>/dev/null || true
  [[ -f /etc/apt/sources.list ]] && cp /etc/apt/sources.list "$apt_dir/sources/debian.list"
  # An apt of its own whose only architecture is arm64 and whose status is empty, so it resolves every dependency.
  cat >"$apt_dir/apt.conf" <<EOF
APT::Architecture "arm64";
APT::Architectures { "arm64"; };
APT::Install-Recommends "false";
APT::Sandbox::User "$(id -un)";
Dir::State "$apt_dir/state";
Dir::State::status "$apt_dir/state/status";
Dir::Cache "$apt_dir/cache";
Dir::Etc::SourceList "/dev/null";
Dir::Etc::SourceParts "$apt_dir/sources";
EOF
  export APT_CONFIG=$apt_dir/apt.conf
  apt-get update -qq
  apt-get install -y -qq --download-only "${packages[@]}" >/dev/null
  # libopencv-dev holds OpenCV's CMake package; its other dependencies are modules patrolmap does not link.
  (cd "$apt_dir/debs" && apt-get download -qq libopencv-dev)
  # .sonames: each shared library's file name with its package and version, for the arm64 package's Depends.
  for deb in "$apt_dir"/cache/archives/*.deb "$apt_dir"/debs/*.deb; do
    dpkg-deb -x "$deb" "$sysroot"
    dpkg-deb -c "$deb" | awk -v package="$(dpkg-deb -f "$deb" Package)" -v version="$(dpkg-deb -f "$deb" Version)" \
      '$6 ~ /\.so\.[0-9]/ { n = split($6, path, "/"); print path[n], package, version }'
  done >"$sysroot/.sonames"
  # What the packages' maintainer scripts would have done: absolute symbolic links point into the sysroot, and
  # BLAS and LAPACK (Debian's alternatives) are ATLAS's, as Ceres's CMake package names.
  while IFS= read -r link; do
    ln -sfnr "$sysroot$(readlink "$link")" "$link"
  done < <(find "$sysroot" -type l -lname '/*')
  lib=$sysroot/usr/lib/aarch64-linux-gnu
  for name in libblas liblapack; do
    ln -sfn "atlas/$name.so.3" "$lib/$name.so.3"
    ln -sfn "atlas/$name.so" "$lib/$name.so"
  done
  # Ceres's CMake package names its libraries by absolute path.
  sed -i "s|/usr/lib/aarch64-linux-gnu/lib|$lib/lib|g" "$lib/cmake/Ceres/CeresTargets.cmake"
  # OpenCV's CMake package checks that every module's library exists; only the modules patrolmap links are here.
  modules=$lib/cmake/opencv4/OpenCVModules-release.cmake
  for target in $(sed -n 's/^list(APPEND _cmake_import_check_targets \(opencv_[a-z0-9_]*\) )$/\1/p' "$modules"); do
    [[ -e $lib/lib$target.so.406 ]] || sed -i "/_cmake_import_check_targets $target )/d" "$modules"
  done
  echo "$want" >"$sysroot/.packages"
  rm -rf "$apt_dir/cache/archives"
fi

stage "cross-building patrolmap and patrolmap-onboard"
cmake -S . -B "$out/build" -DCMAKE_TOOLCHAIN_FILE="$root/cmake/aarch64-linux-gnu.cmake" \
  -DPATROLMAP_ARM64_SYSROOT="$sysroot" -DCMAKE_BUILD_TYPE=Release -DPATROLMAP_BUILD_TESTS=OFF \
  -DPATROLMAP_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$out/build" -j "$(nproc)" --target patrolmap patrolmap-onboard
readelf -h "$out/build/tools/patrolmap" | grep -q AArch64 || { echo "cross_arm64: not an arm64 binary" >&2; exit 1; }

# The arm64 Debian packages. Depends: the package of each shared library the programs load, as dpkg-shlibdeps would
# name it from an arm64 machine's dpkg database.
stage "packaging"
depends=()
for soname in $(readelf -d "$out/build/tools/patrolmap" "$out/build/tools/patrolmap-onboard" |
  sed -n 's/.*Shared library: \[\(.*\)\]/\1/p' | sort -u); do
  entry=$(awk -v name="$soname" '$1 == name { print $2 " (>= " $3 ")"; exit }' "$sysroot/.sonames")
  [[ -n $entry ]] || { echo "cross_arm64: no package in the sysroot holds $soname" >&2; exit 1; }
  depends+=("$entry")
done
depends_line=$(printf '%s\n' "${depends[@]}" | sort -u | paste -sd, - | sed 's/,/, /g')
cmake "$out/build" -DPATROLMAP_DEB_RUNTIME_DEPENDS="$depends_line" >/dev/null
rm -rf "$out/packages"
(cd "$out/build" && cpack -G DEB -B "$out/packages" >"$out/cpack.log" 2>&1) || { tail "$out/cpack.log" >&2; exit 1; }
deb=$(ls "$out"/packages/patrolmap_*_arm64.deb)
echo "$(basename "$deb"): Depends: $(dpkg-deb -f "$deb" Depends)"

# 3. One short series through both builds. qemu-aarch64-static runs the arm64 binaries with the sysroot's loader
# and libraries; each build reads the same files (PATROLMAP_VOCABULARY: the shipped vocabulary).
amd64=$root/build/tools
arm64=$out/build/tools
[[ -x $amd64/patrolmap ]] || { echo "cross_arm64: build the amd64 binaries first (scripts/build.sh)" >&2; exit 1; }
runs=$out/runs
rm -rf "$runs"
mkdir -p "$runs"
export PATROLMAP_VOCABULARY=$root/vocab/default.pmvoc
qemu=(qemu-aarch64-static -L "$sysroot")
stage "simulating the series (376x240, two flights of about 620 frames, 12 objects with detections and depth)"
"$amd64/patrolmap" simulate --route l-shape --speed 4 --flights 2 --objects 12 --detections --depth \
  --resolution 376x240 --seed 9 --out "$runs/series" >/dev/null
# Runs one command of an architecture's run, its output in that run's log, shown when it fails.
step() {
  local log=$1
  shift
  "$@" >>"$log" 2>&1 || { tail -n 30 "$log" >&2; echo "cross_arm64: failed: $*" >&2; exit 1; }
}
# The runs after `map` read only its map, so they go side by side: under qemu each takes minutes.
dpkg-deb -x "$deb" "$runs/package"
for arch in amd64 arm64; do
  run=()
  [[ $arch == arm64 ]] && run=("${qemu[@]}")
  bin=${!arch}
  stage "$arch: map, then patrol and patrolmap-onboard --fast side by side"
  step "$runs/map-$arch.log" "${run[@]}" "$bin/patrolmap" map "$runs/series/flight_1" --out "$runs/map-$arch"
  step "$runs/patrol-$arch.log" "${run[@]}" "$bin/patrolmap" patrol "$runs/series/flight_2" \
    --map "$runs/map-$arch/map.pmap" --out "$runs/patrol-$arch" &
  patrol=$!
  step "$runs/onboard-$arch.log" "${run[@]}" "$bin/patrolmap-onboard" "$runs/series/flight_2" \
    --map "$runs/map-$arch/map.pmap" --fast --out "$runs/onboard-$arch" &
  onboard=$!
  # The packaged program, unpacked as dpkg lays it out, finds its own vocabulary and maps as the build tree's does.
  if [[ $arch == arm64 ]]; then
    (step "$runs/package.log" env PATROLMAP_VOCABULARY= "${qemu[@]}" "$runs/package/usr/bin/patrolmap" map \
      "$runs/series/flight_1" --out "$runs/package-map") || { kill "$patrol" "$onboard"; exit 1; }
  fi
  wait "$patrol" || exit 1
  wait "$onboard" || exit 1
done
for what in map patrol onboard; do
  python3 tests/arm64/compare_runs.py "$runs/$what-amd64" "$runs/$what-arm64"
done
python3 tests/arm64/compare_runs.py "$runs/map-amd64" "$runs/package-map"
stage "done"
