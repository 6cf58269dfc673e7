# Sourced by map_task.sh and merge_task.sh: runs a command that writes a folder, in a scratch folder beside
# the destination, and renames it into place when it succeeds, so a killed task leaves no half-written
# output and a finished one is never redone.
#   publish OUT COMMAND...   COMMAND is run with -o SCRATCH appended
publish() {
  local out=$1 scratch
  shift
  mkdir -p "$(dirname "$out")"
  scratch=$(mktemp -d "$(dirname "$out")/.$(basename "$out").XXXXXX")
  trap 'rm -rf "$scratch"' EXIT
  "$@" -o "$scratch"
  rm -rf "$out"
  chmod 755 "$scratch"
  mv "$scratch" "$out"
  trap - EXIT
}
