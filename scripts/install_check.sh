#!/usr/bin/env bash
# Installs the amd64 Debian package as a user would (`apt-get install ./patrolmap_*_amd64.deb`), maps the sample
# flight log with the installed program from a folder outside the repository, runs the installed onboard program,
# and removes the package again (unless it was installed before). Part of scripts/test.sh; needs root or sudo
# without a password, and says so and stops (exit 0) without them. Usage: scripts/install_check.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
build=$(realpath "${1:-build}")
sudo=""
if [[ $(id -u) -ne 0 ]]; then
  if sudo -n true 2>/dev/null; then sudo=sudo; else
    echo "install_check: skipped: installing a package needs root or sudo"
    exit 0
  fi
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
(cd "$build" && cpack -G DEB -B "$work/packages" >"$work/cpack.log" 2>&1) || { tail "$work/cpack.log" >&2; exit 1; }
deb=$(ls "$work"/packages/patrolmap_*_amd64.deb)
installed_before=false
dpkg-query -W -f='${Status}' patrolmap 2>/dev/null | grep -q "install ok installed" && installed_before=true
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "$deb" >"$work/apt.log" 2>&1 ||
  { tail "$work/apt.log" >&2; exit 1; }
remove() { $installed_before || DEBIAN_FRONTEND=noninteractive $sudo apt-get remove -y -qq patrolmap >/dev/null 2>&1; }
trap 'remove; rm -rf "$work"' EXIT
cd "$work"
# The installed program finds the vocabulary it ships, not the source tree's.
out=$(env PATROLMAP_VOCABULARY= /usr/bin/patrolmap map "$root/flight_logs/sample" --out "$work/map" 2>&1) ||
  { echo "$out" >&2; echo "install_check: the installed patrolmap failed to map the sample log" >&2; exit 1; }
grep -E "1 log: [0-9]+ nodes" <<<"$out" >/dev/null ||
  { echo "$out" >&2; echo "install_check: no map summary" >&2; exit 1; }
/usr/bin/patrolmap-onboard --help >/dev/null
echo "install_check: $(basename "$deb") installed; /usr/bin/patrolmap mapped flight_logs/sample from $work:" \
  "$(grep -oE '1 log: [0-9]+ nodes, [0-9]+ loop closures?' <<<"$out")"
