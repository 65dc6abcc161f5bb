# The ways out that a simulator cannot show, over the fake BlueZ (docs/safety.md): every car is
# checked in the fake's own summary (its target speed, what the car itself was last told).
# - the watchdog: C code that never returns holds the loop; within about a second, every car
#   gets its stop from a thread outside the loop
# - the last-resort exit (a third signal the wedged loop never answered) sends the stops first
# - both where BlueZ refuses AcquireWrite (--no-acquire): the stops then go by WriteValue
# - Ctrl-Z stops the cars before the process stops
# - a start refused for --keyboard without a terminal connects no car; one refused by a broker
#   that cannot be reached, after the cars connected, stops them
source "$(dirname "$0")/ble_lib.sh"
NAGGING="$SRC/tests/integration/nagging.lua"
start_bus

# target_speeds: "ADDR target=N" for both fake cars, from the fake's summary (after stop_fake)
target_speeds() {
  sed -n 's/^\(E0:00:00:00:00:0[12]\) .*\(target=[0-9-]*\).*/\1 \2/p' "$TMP/fake.out"
}
both_stopped=$'E0:00:00:00:00:01 target=0\nE0:00:00:00:00:02 target=0'

# run_bg NAME ENV…: nagging.lua over --ble in the background, its stdout on fd 4 (run_fifo)
run_bg() {
  local name=$1
  shift
  run_fifo "$name" env "$@" $PITWALL run "$NAGGING" --ble --scan-timeout 0.5
}

# watchdog_case NAME FAKE_ARGS…: the loop wedged in string.find, nobody sends a signal: the
# watchdog stops both cars while the loop is still stuck
watchdog_case() {
  local name=$1
  shift
  start_fake --adapters 1 --cars 2 "$@"
  run_bg "$name" MODE=wedge
  expect_wedged "$name"
  contains "$name: stderr says it stopped the cars" "the watchdog sent 2 cars its stop" \
    "$(cat "$TMP/$name.err")"
  stop_fake  # while pitwall is still wedged: what the cars were last told
  check "$name: both cars were told to stop while the loop was stuck" "$both_stopped" \
    "$(target_speeds)"
  end_fifo
}

# last_resort_case NAME WATCHDOG_SECONDS FAKE_ARGS…: the loop wedged, signals until the
# handler itself ends the process; it sends the stops first
last_resort_case() {
  local name=$1 watchdog=$2
  shift 2
  start_fake --adapters 1 --cars 2 "$@"
  run_bg "$name" MODE=wedge PITWALL_WATCHDOG="$watchdog"
  read -r -t 20 -u 4 line
  check "$name: the script wedges the loop" "wedging" "$line"
  cat <&4 >/dev/null 2>&1 &
  for _ in $(seq 1 100); do  # two kinds, so that no two are pending at once and merge
    kill -INT $RUN_PID 2>/dev/null || break
    kill -TERM $RUN_PID 2>/dev/null || break
    sleep 0.05
  done
  wait_bounded $RUN_PID
  check "$name: exit status" 130 $?
  exec 4<&-
  contains "$name: the handler sent the stops and left" \
    "every car sent its stop from outside the loop; leaving now" "$(cat "$TMP/$name.err")"
  check "$name: not the watchdog's doing" "" "$(grep "has not turned for" "$TMP/$name.err")"
  stop_fake
  check "$name: both cars were told to stop" "$both_stopped" "$(target_speeds)"
}

# --- the watchdog, through the cars' write sockets
watchdog_case watchdog
# --- the watchdog where BlueZ gives no write socket (writes go by WriteValue, on the loop's own
# bus connection): the stops go as WriteValue calls on a connection the watchdog's thread makes
watchdog_case watchdog-call --no-acquire
# --- the last-resort exit with no watchdog (PITWALL_WATCHDOG=0): through the write sockets
last_resort_case last-resort 0
# --- the last-resort exit over WriteValue: a signal handler cannot make a D-Bus call; it asks
# the watchdog's thread (whose own limit, 60 s, is far off) and waits for it before it leaves
last_resort_case last-resort-call 60 --no-acquire

# --- Ctrl-Z: the stops reach the cars before the process stops
start_fake --adapters 1 --cars 2
run_bg tstp MODE=none
cat <&4 >/dev/null 2>&1 &
kill -TSTP $RUN_PID
wait_suspended $RUN_PID
stop_fake  # the fake ends while pitwall is suspended: what the cars were last told
check "Ctrl-Z: both cars were stopped before the process stopped" "$both_stopped" \
  "$(target_speeds)"
kill -CONT $RUN_PID
kill -INT $RUN_PID
wait_bounded $RUN_PID
check "Ctrl-Z, fg, Ctrl-C: exit status" 130 $?
exec 4<&-

# --- refused starts
start_fake --adapters 1 --cars 2
MODE=none $PITWALL run "$NAGGING" --ble --scan-timeout 0.5 --humans 1 --keyboard </dev/null \
  >/dev/null 2>"$TMP/keyboard.err"
check "--keyboard without a terminal: refused" 2 $?
stop_fake
contains "--keyboard without a terminal: no car was connected" \
  "E0:00:00:00:00:01 connected=false target=0 connects=0" "$(cat "$TMP/fake.out")"

start_fake --adapters 1 --cars 2
MODE=none $PITWALL run "$NAGGING" --ble --scan-timeout 0.5 --mqtt mqtt://127.0.0.1:1 \
  --remote-cars 1 --mqtt-timeout 1 </dev/null >/dev/null 2>"$TMP/broker.err"
check "a broker that cannot be reached: refused" 2 $?
stop_fake
check "a broker that cannot be reached: the connected cars were stopped" "$both_stopped" \
  "$(target_speeds)"

finish
