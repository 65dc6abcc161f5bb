# The stop is the last word over Bluetooth LE too (docs/safety.md): tests/integration/nagging.lua
# commands its cars every 20 ms and on every position event; against the fake BlueZ, after every
# way a run ends — --duration, pitwall.stop(), a dying main chunk, os.exit, the memory cap,
# SIGINT, SIGTERM — every car is left with target speed 0 (the stop was the last speed command it
# got) and disconnected.
source "$(dirname "$0")/ble_lib.sh"
NAGGING="$SRC/tests/integration/nagging.lua"
start_bus

# stopped NAME: both fake cars ended stopped and disconnected (the fake's summary, after it ended)
stopped() {
  stop_fake
  local summary n
  summary=$(cat "$TMP/fake.out")
  for n in 1 2; do
    contains "$1: car $n left stopped and disconnected" \
      "E0:00:00:00:00:0$n connected=false target=0" "$summary"
  done
}

# MODE STATUS [OPTION…]: the way the run ends, the exit status it must end with
while read -r mode status options; do
  start_fake --adapters 1 --cars 2
  MODE=$mode $PITWALL run "$NAGGING" --ble --scan-timeout 0.5 $options </dev/null \
    >"$TMP/$mode.out" 2>"$TMP/$mode.err"
  check "$mode: exit status" "$status" $?
  stopped "$mode"
done <<'MODES'
none 0 --duration 2
stop 0
error 1
exit 3
memory 1 --lua-memory 64 --budget 0
MODES
contains "pitwall.stop(): a command after it is refused" "takes no more commands" \
  "$(cat "$TMP/stop.out")"

# Ctrl-C and SIGTERM while the script keeps commanding
for sig in INT TERM; do
  start_fake --adapters 1 --cars 2
  rm -f "$TMP/run.fifo"
  mkfifo "$TMP/run.fifo"
  MODE=none $PITWALL run "$NAGGING" --ble --scan-timeout 0.5 >"$TMP/run.fifo" 2>"$TMP/$sig.err" &
  RUN_PID=$!
  exec 4<"$TMP/run.fifo"
  read -r -t 20 -u 4 line
  check "SIG$sig: the script is driving" "driving" "$line"
  kill -$sig $RUN_PID
  cat <&4 >/dev/null 2>&1 &
  wait $RUN_PID
  check "SIG$sig: exit status" 130 $?
  exec 4<&-
  stopped "SIG$sig"
done

finish
