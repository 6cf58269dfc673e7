#!/usr/bin/env bash
# Installs the Debian 12 packages patrolmap builds with (only the missing ones):
#   scripts/install_deps.sh            the build and test dependencies
#   scripts/install_deps.sh PACKAGE…   these packages instead (scripts that need more, e.g. photographs)
set -euo pipefail
packages=(build-essential cmake pkg-config libopencv-dev libeigen3-dev libboost-graph-dev libceres-dev
  libyaml-cpp-dev libcli11-dev libspdlog-dev nlohmann-json3-dev libgtest-dev libgmock-dev libbenchmark-dev
  libnanoflann-dev librsvg2-bin opencv-doc libxml2-utils graphviz python3-networkx python3-jsonschema chromium)
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
