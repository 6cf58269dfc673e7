# Shared by the shell tests (source it): a scratch folder $work removed on exit, and counted checks.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
passes=0

expect() {  # expect NAME WANTED_CODE PATTERN -- COMMAND...: exit code and a line of output matching PATTERN
  local name=$1 wanted=$2 pattern=$3
  shift 4
  local output code
  output=$("$@" 2>&1)
  code=$?
  if [[ $code -ne $wanted ]] || ! grep -qE -- "$pattern" <<<"$output"; then
    echo "FAIL $name: exit $code (wanted $wanted), output:"
    echo "$output" | head -5
    failures=$((failures + 1))
  else
    passes=$((passes + 1))
  fi
}

check() {  # check NAME COMMAND...: the command succeeds
  local name=$1
  shift
  if "$@"; then passes=$((passes + 1)); else echo "FAIL $name"; failures=$((failures + 1)); fi
}

finish() {  # finish SUITE: prints the counts; the exit status says whether all passed
  echo "$1: $passes passed, $failures failed"
  [[ $failures -eq 0 ]]
}
