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

# contains NAME NEEDLE HAYSTACK (an empty needle fails: it would match anything)
contains() {
  [ -n "$2" ] || { fail "$1: nothing to look for (an empty needle matches anything)"; return; }
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

# The last frame sent to each car, as "CAR NAME SPEED" (SPEED only for set-speed).
last_tx_per_car() {
  python3 - "$1" <<'PY'
import json, sys
last = {}
for line in open(sys.argv[1]):
    r = json.loads(line)
    if r.get("dir") == "tx":  # (a race's own lines in a record have no "dir")
        last[r["car"]] = r["msg"]
for car in sorted(last):
    m = last[car]
    print(car, m["name"], m.get("speed_mm_s", ""))
PY
}

# expect_stopped NAME RECORD CARS: the last frame to each of cars 1..CARS in RECORD is its stop
expect_stopped() {
  local want="" i
  for i in $(seq 1 "$3"); do want+="$i set-speed 0"$'\n'; done
  check "$1: the last frame to every car is its stop" "${want%$'\n'}" "$(last_tx_per_car "$2")"
}

# wait_bounded PID: PID's exit status; a run that outlives 30 s is killed (status 137) so that a
# signal that never arrives fails the check instead of hanging the test.
# (The timer is killed with SIGKILL, which runs no trap: a subshell killed right after its fork
# still has the test's EXIT trap and would remove $TMP. Its sleep, orphaned, holds no pipe.)
wait_bounded() {
  (sleep 30 && kill -9 "$1") >/dev/null 2>&1 &
  local watchdog=$! status
  wait "$1"
  status=$?
  kill -9 "$watchdog" 2>/dev/null
  wait "$watchdog" 2>/dev/null
  return $status
}

# run_fifo NAME COMMAND…: COMMAND in the background (its pid in RUN_PID), stdin /dev/null,
# stderr in $TMP/NAME.err, stdout read through a FIFO on fd 4 until its first line, which must
# be "driving" (tests/integration/nagging.lua and the like say it once they command the cars), or
# $RUN_FIFO_SAYS when that is set.
run_fifo() {
  local name=$1 line want=${RUN_FIFO_SAYS:-driving}
  shift
  rm -f "$TMP/run.fifo"
  mkfifo "$TMP/run.fifo"
  "$@" </dev/null >"$TMP/run.fifo" 2>"$TMP/$name.err" &
  RUN_PID=$!
  exec 4<"$TMP/run.fifo"
  read -r -t 20 -u 4 line
  check "$name: the script says it is $want" "$want" "$line"
}

# expect_wedged NAME: the script run by run_fifo says it wedges its loop in C code, and the
# watchdog (engine/core/emergency_stops) then says on stderr that it sent N cars their stop.
expect_wedged() {
  local line
  read -r -t 20 -u 4 line
  check "$1: the script wedges the loop" "wedging" "$line"
  wait_for "$TMP/$1.err" "has not turned for" 20 || fail "$1: the watchdog said nothing"
}

# end_fifo: kills the run_fifo run for good (SIGKILL: it may be wedged) and closes fd 4.
end_fifo() {
  kill -9 "$RUN_PID" 2>/dev/null
  wait "$RUN_PID" 2>/dev/null
  exec 4<&-
}

# wait_suspended PID: until PID is stopped (Ctrl-Z suspended it), at most 20 s.
wait_suspended() {
  local deadline=$((SECONDS + 20))
  until [ "$(sed 's/.*) //' "/proc/$1/stat" 2>/dev/null | cut -d' ' -f1)" = T ] ||
    [ $SECONDS -ge $deadline ]; do sleep 0.02; done
}

finish() {
  [ "$FAILURES" -eq 0 ] || { echo "$FAILURES check(s) failed"; exit 1; }
}

# good_class DIR: four good driver files, as a class hands them in (the league, standings and
# final tests): alice (tests/integration/drivers/good.lua), bob (a cruiser at 1100 mm/s), carol
# (the shipped overtaker) and dave (the shipped follower).
good_class() {
  mkdir -p "$1"
  cp "$SRC/tests/integration/drivers/good.lua" "$1/alice.lua"
  cat > "$1/bob.lua" <<'LUA'
local cruiser = require "pitwall.drivers.cruiser"
return { name = "bob", new = function() return cruiser.new { speed = 1100 } end }
LUA
  printf 'return require "pitwall.drivers.overtaker"\n' > "$1/carol.lua"
  printf 'return require "pitwall.drivers.follower"\n' > "$1/dave.lua"
}
