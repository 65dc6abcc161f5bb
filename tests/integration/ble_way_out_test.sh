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

# run_bg NAME ENV…: nagging.lua over --ble in the background, its stdout read through a FIFO on
# fd 4 until "driving"
run_bg() {
  local name=$1
  shift
  rm -f "$TMP/run.fifo"
  mkfifo "$TMP/run.fifo"
  env "$@" $PITWALL run "$NAGGING" --ble --scan-timeout 0.5 >"$TMP/run.fifo" \
    2>"$TMP/$name.err" &
  RUN_PID=$!
  exec 4<"$TMP/run.fifo"
  read -r -t 20 -u 4 line
  check "$name: the script is driving" "driving" "$line"
}

# --- the watchdog: the loop wedged in string.find; nobody sends a signal
start_fake --adapters 1 --cars 2
run_bg watchdog MODE=wedge
read -r -t 20 -u 4 line
check "watchdog: the script wedges the loop" "wedging" "$line"
wait_for "$TMP/watchdog.err" "has not turned for" 20
contains "watchdog: stderr says it stopped the cars" "the watchdog sent 2 cars its stop" \
  "$(cat "$TMP/watchdog.err")"
stop_fake  # while pitwall is still wedged: what the cars were last told
check "watchdog: both cars were told to stop while the loop was stuck" "$both_stopped" \
  "$(target_speeds)"
kill -9 $RUN_PID
wait $RUN_PID 2>/dev/null
exec 4<&-

# --- the watchdog where BlueZ gives no write socket (writes go by WriteValue, on the loop's own
# bus connection): the stops go as WriteValue calls on a connection the watchdog's thread makes
start_fake --adapters 1 --cars 2 --no-acquire
run_bg watchdog-call MODE=wedge
read -r -t 20 -u 4 line
check "watchdog, WriteValue: the script wedges the loop" "wedging" "$line"
wait_for "$TMP/watchdog-call.err" "has not turned for" 20
contains "watchdog, WriteValue: stderr says it stopped the cars" "the watchdog sent 2 cars its stop" \
  "$(cat "$TMP/watchdog-call.err")"
stop_fake
check "watchdog, WriteValue: both cars were told to stop while the loop was stuck" \
  "$both_stopped" "$(target_speeds)"
kill -9 $RUN_PID
wait $RUN_PID 2>/dev/null
exec 4<&-

# --- the last-resort exit over WriteValue: a signal handler cannot make a D-Bus call; it asks
# the watchdog's thread (whose own limit, 60 s, is far off) and waits for it before it leaves
start_fake --adapters 1 --cars 2 --no-acquire
run_bg last-resort-call MODE=wedge PITWALL_WATCHDOG=60
read -r -t 20 -u 4 line
check "last resort, WriteValue: the script wedges the loop" "wedging" "$line"
cat <&4 >/dev/null 2>&1 &
for _ in $(seq 1 100); do
  kill -INT $RUN_PID 2>/dev/null || break
  kill -TERM $RUN_PID 2>/dev/null || break
  sleep 0.05
done
wait_bounded $RUN_PID
check "last resort, WriteValue: exit status" 130 $?
exec 4<&-
check "last resort, WriteValue: not the watchdog's doing" "" \
  "$(grep "has not turned for" "$TMP/last-resort-call.err")"
stop_fake
check "last resort, WriteValue: both cars were told to stop" "$both_stopped" "$(target_speeds)"

# --- the last-resort exit: no watchdog (PITWALL_WATCHDOG=0), the loop wedged, signals until
# the handler itself ends the process
start_fake --adapters 1 --cars 2
run_bg last-resort MODE=wedge PITWALL_WATCHDOG=0
read -r -t 20 -u 4 line
check "last resort: the script wedges the loop" "wedging" "$line"
cat <&4 >/dev/null 2>&1 &
for _ in $(seq 1 100); do  # two kinds, so that no two are pending at once and merge
  kill -INT $RUN_PID 2>/dev/null || break
  kill -TERM $RUN_PID 2>/dev/null || break
  sleep 0.05
done
wait_bounded $RUN_PID
check "last resort: exit status" 130 $?
exec 4<&-
contains "last resort: the handler sent the stops and left" \
  "every car sent its stop from outside the loop; leaving now" "$(cat "$TMP/last-resort.err")"
stop_fake
check "last resort: both cars were told to stop" "$both_stopped" "$(target_speeds)"

# --- Ctrl-Z: the stops reach the cars before the process stops
start_fake --adapters 1 --cars 2
run_bg tstp MODE=none
cat <&4 >/dev/null 2>&1 &
kill -TSTP $RUN_PID
deadline=$((SECONDS + 20))
until [ "$(sed 's/.*) //' /proc/$RUN_PID/stat | cut -d' ' -f1)" = T ] || [ $SECONDS -ge $deadline ]
do sleep 0.02; done
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
