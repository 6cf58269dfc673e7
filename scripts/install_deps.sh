#!/usr/bin/env bash
# Installs the Debian 12 packages patrolmap builds with (only the missing ones); ROS bags are read with
# librosbag-storage-dev (ROS 1) and libsqlite3-dev (ROS 2), and the tests write bags with python3-rosbag; the
# fleet test runs scripts/fleet/ with GNU parallel (parallel) and on a Slurm cluster on localhost (slurm-wlm, munge);
# the vocabulary test trains on the photographs of mate-backgrounds and lomiri-wallpapers-16.04; the arm64 check
# (scripts/cross_arm64.sh) cross-compiles with crossbuild-essential-arm64 and runs under qemu-user-static:
#   scripts/install_deps.sh            the build and test dependencies
#   scripts/install_deps.sh PACKAGE…   these packages instead (scripts that need more, e.g. photographs)
set -euo pipefail
packages=(build-essential cmake pkg-config libopencv-dev libeigen3-dev libboost-graph-dev libceres-dev
  libyaml-cpp-dev libcli11-dev libspdlog-dev nlohmann-json3-dev libgtest-dev libgmock-dev libbenchmark-dev
  libnanoflann-dev librsvg2-bin opencv-doc libxml2-utils graphviz python3-networkx python3-jsonschema chromium
  librosbag-storage-dev libsqlite3-dev python3-rosbag python3-sensor-msgs python3-geometry-msgs python3-nav-msgs
  python3-tf2-msgs python3-opencv python3-yaml sqlite3 parallel slurm-wlm munge mate-backgrounds
  lomiri-wallpapers-16.04 crossbuild-essential-arm64 qemu-user-static)
(($#)) && packages=("$@")
missing=()
for package in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
done
if ((${#missing[@]})); then
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  echo "installing: ${missing[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi
