# Shared by the integration tests: $PITWALL is the binary, $SRC the source tree, $TMP a scratch
# folder removed at exit. check/fail report what was expected and what happened.
set -uo pipefail
PITWALL=$1
SRC=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
FAILURES=0

fail() {
  echo "FAIL: $*"
  FAILURES=$((FAILURES + 1))
}

# check NAME EXPECTED ACTUAL
check() {
  if [ "$2" != "$3" ]; then fail "$1: expected [$2], got [$3]"; else echo "ok: $1"; fi
}

# contains NAME NEEDLE HAYSTACK
contains() {
  case "$3" in
    *"$2"*) echo "ok: $1" ;;
    *) fail "$1: expected to contain [$2], got [$3]" ;;
  esac
}

# wait_for FILE PATTERN [SECONDS]: until FILE has a line matching PATTERN (grep -E), at most
# SECONDS (default 20): it awaits output, polling the file. False when it never came.
wait_for() {
  local deadline=$((SECONDS + ${3:-20}))
  until grep -qE -- "$2" "$1" 2>/dev/null; do
    [ $SECONDS -ge $deadline ] && return 1
    sleep 0.02
  done
}

finish() {
  [ "$FAILURES" -eq 0 ] || { echo "$FAILURES check(s) failed"; exit 1; }
}
