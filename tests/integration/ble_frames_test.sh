# Frames over Bluetooth LE, both ways of carrying them, and bad ones (fake BlueZ, real D-Bus).
source "$(dirname "$0")/ble_lib.sh"
start_bus
A1=E0:00:00:00:00:01

field() {  # field NAME LINE
  echo "$2" | sed -n "s/.* $1=\([^ ]*\).*/\1/p"
}

# Malformed notifications: reported to the script and the log, the race goes on
start_fake --cars 1 --garbage $A1@1
out=$(CROSSINGS=2 SPEED=1200 TIMEOUT=30 $PITWALL run "$SRC/tests/ble/laps.lua" --ble \
  --scan-timeout 0.5 2>"$TMP/garbage.err"); rc=$?
check "garbage: the race finishes" 0 "$rc"
line=$(echo "$out" | grep "^car ble:$A1 ")
check "garbage: both malformed frames reached onMalformed" 2 "$(field malformed "$line")"
check "garbage: still connected" true "$(field connected "$line")"
contains "garbage: the log names the frame's id and lengths" "0x17" "$(cat "$TMP/garbage.err")"
stop_fake

# Sockets (AcquireNotify/AcquireWrite) are used where BlueZ offers them ...
start_fake --cars 1
CROSSINGS=2 SPEED=1200 TIMEOUT=30 $PITWALL --log-level debug run "$SRC/tests/ble/laps.lua" --ble \
  --scan-timeout 0.5 >/dev/null 2>"$TMP/acquire.err"; rc=$?
check "acquire: exit status" 0 "$rc"
contains "acquire: frames through sockets" "notifications by socket, writes by socket" \
  "$(cat "$TMP/acquire.err")"
stop_fake

# ... and signals and method calls where it does not
start_fake --cars 1 --no-acquire
CROSSINGS=2 SPEED=1200 TIMEOUT=30 $PITWALL --log-level debug run "$SRC/tests/ble/laps.lua" --ble \
  --scan-timeout 0.5 >/dev/null 2>"$TMP/noacquire.err"; rc=$?
check "no acquire: exit status" 0 "$rc"
contains "no acquire: frames through signals and calls" "notifications by signal, writes by call" \
  "$(cat "$TMP/noacquire.err")"
stop_fake
contains "no acquire: the fake got the frames" "framesToCar=" "$(cat "$TMP/fake.out")"

finish
