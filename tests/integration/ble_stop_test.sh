# The stop is the last word over Bluetooth LE too (docs/safety.md): tests/integration/nagging.lua
# commands its cars every 20 ms and on every position event; against the fake BlueZ, after
# pitwall.stop() and after Ctrl-C, every car is left with target speed 0 — the stop was the last
# speed command it got — and disconnected.
source "$(dirname "$0")/ble_lib.sh"
NAGGING="$SRC/tests/integration/nagging.lua"
start_bus

# pitwall.stop(), with commands right after it
start_fake --adapters 1 --cars 2
MODE=stop $PITWALL run "$NAGGING" --ble --scan-timeout 0.5 >"$TMP/stop.out" 2>"$TMP/stop.err"
check "pitwall.stop(): exit status" 0 $?
contains "pitwall.stop(): a command after it is refused" "takes no more commands" \
  "$(cat "$TMP/stop.out")"
stop_fake
summary=$(cat "$TMP/fake.out")
for n in 1 2; do
  contains "pitwall.stop(): car $n left stopped and disconnected" \
    "E0:00:00:00:00:0$n connected=false target=0" "$summary"
done

# Ctrl-C while the script keeps commanding
start_fake --adapters 1 --cars 2
mkfifo "$TMP/run.fifo"
MODE=none $PITWALL run "$NAGGING" --ble --scan-timeout 0.5 >"$TMP/run.fifo" 2>"$TMP/int.err" &
RUN_PID=$!
exec 4<"$TMP/run.fifo"
read -r -t 20 -u 4 line
check "ctrl-c: the script is driving" "driving" "$line"
kill -INT $RUN_PID
cat <&4 >/dev/null 2>&1 &
wait $RUN_PID
check "ctrl-c: exit status" 130 $?
stop_fake
summary=$(cat "$TMP/fake.out")
for n in 1 2; do
  contains "ctrl-c: car $n left stopped and disconnected" \
    "E0:00:00:00:00:0$n connected=false target=0" "$summary"
done

finish
