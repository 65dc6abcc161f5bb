# Frames over Bluetooth LE, both ways of carrying them, and bad ones (fake BlueZ, real D-Bus).
source "$(dirname "$0")/ble_lib.sh"
start_bus
A1=E0:00:00:00:00:01

# Malformed notifications: reported to the script and the log, the race goes on
start_fake --cars 1 --garbage $A1@1
drive garbage CROSSINGS=2 SPEED=1200 TIMEOUT=30
check "garbage: the race finishes" 0 "$RC"
line=$(echo "$OUT" | grep "^car ble:$A1 ")
check "garbage: both malformed frames reached onMalformed" 2 "$(field malformed "$line")"
check "garbage: still connected" true "$(field connected "$line")"
contains "garbage: the log names the frame's id and lengths" "0x17" "$(cat "$TMP/garbage.err")"
stop_fake

# Sockets (AcquireNotify/AcquireWrite) where BlueZ offers them, signals and method calls where
# it does not
for mode in acquire no-acquire; do
  flags=() paths="notifications by socket, writes by socket"
  [ $mode = no-acquire ] && flags=(--no-acquire) paths="notifications by signal, writes by call"
  start_fake --cars 1 "${flags[@]}"
  CROSSINGS=2 SPEED=1200 TIMEOUT=30 $PITWALL --log-level debug run "$SRC/tests/ble/laps.lua" \
    --ble --scan-timeout 0.5 >/dev/null 2>"$TMP/$mode.err"; rc=$?
  check "$mode: exit status" 0 "$rc"
  contains "$mode: $paths" "$paths" "$(cat "$TMP/$mode.err")"
  stop_fake
  sent=$(field framesToCar "$(cat "$TMP/fake.out")")
  [ "${sent:-0}" -gt 3 ] && echo "ok: $mode: the car got the commands ($sent frames)" ||
    fail "$mode: the car got ${sent:-0} frames"
done

finish
