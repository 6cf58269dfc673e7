#!/usr/bin/env bash
# The shipped vocabulary is what scripts/build_vocabulary.sh builds, byte for byte.
# Usage: vocabulary_test.sh PATROLMAP_BINARY SOURCE_DIR
set -euo pipefail
bin=$1
source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
TMPDIR=$work PATROLMAP_BIN=$bin bash "$source_dir/scripts/build_vocabulary.sh" "$work/default.pmvoc" >"$work/log" 2>&1 || {
  cat "$work/log" >&2
  exit 1
}
if ! cmp -s "$work/default.pmvoc" "$source_dir/vocab/default.pmvoc"; then
  echo "vocab/default.pmvoc is not what scripts/build_vocabulary.sh builds: run the script, then measure the" \
    "loop-closure figures again" >&2
  exit 1
fi
echo "vocab/default.pmvoc: rebuilt byte for byte ($(stat -c %s "$work/default.pmvoc") bytes)"
