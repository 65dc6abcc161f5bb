# For the BLE integration tests: a private dbus-daemon and the fake BlueZ (tests/fake_bluez) on
# it, started and stopped by the test. $3 is the fake_bluez binary.
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
FAKE_BLUEZ=$3
BUS_PID=""
FAKE_PID=""
COPY_PID=""

# stop_fake: ends the fake BlueZ and waits until its last words are in $TMP/fake.out.
stop_fake() {
  if [ -n "$FAKE_PID" ]; then
    kill -TERM "$FAKE_PID" 2>/dev/null
    wait "$FAKE_PID" 2>/dev/null
    FAKE_PID=""
  fi
  if [ -n "$COPY_PID" ]; then
    wait "$COPY_PID" 2>/dev/null
    COPY_PID=""
  fi
}

cleanup_ble() {
  stop_fake
  [ -n "$BUS_PID" ] && kill "$BUS_PID" 2>/dev/null
  rm -rf "$TMP"
}
trap cleanup_ble EXIT

# start_bus: a private bus, exported as the system bus for everything started after it.
start_bus() {
  local out
  out=$(dbus-daemon --config-file="$SRC/tests/support/bus.conf" --fork --nosyslog \
    --print-address=1 --print-pid=1) || { echo "cannot start dbus-daemon"; exit 1; }
  export DBUS_SYSTEM_BUS_ADDRESS=$(echo "$out" | sed -n 1p)
  BUS_PID=$(echo "$out" | sed -n 2p)
}

# start_fake ARGS…: the fake BlueZ; returns once it printed "ready". Its stdout is in
# $TMP/fake.out, its stderr in $TMP/fake.err.
start_fake() {
  rm -f "$TMP/fake.fifo"
  mkfifo "$TMP/fake.fifo"
  # Every code: tests/ble/laps.lua counts laps from position updates (34 → 33), which a real
  # car at 1200 mm/s seldom sends on both start pieces; these tests are about the link
  # (docs/simulator.md "Sensor model").
  "$FAKE_BLUEZ" --sensor ideal "$@" >"$TMP/fake.fifo" 2>"$TMP/fake.err" &
  FAKE_PID=$!
  exec 3<"$TMP/fake.fifo"
  local line=""
  read -r -t 10 -u 3 line
  if [ "$line" != "ready" ]; then
    echo "the fake BlueZ did not start: $(cat "$TMP/fake.err")"
    exit 1
  fi
  cat <&3 >"$TMP/fake.out" &  # the rest of its output, for the test to read after stop_fake
  COPY_PID=$!
  exec 3<&-
}

# field NAME LINE: the value of NAME=… in one of laps.lua's summary lines
field() {
  echo "$2" | sed -n "s/.* $1=\([^ ]*\).*/\1/p"
}

# drive NAME [VAR=VALUE…] [-- OPTION…]: runs tests/ble/laps.lua over --ble with those variables
# (CROSSINGS, SPEED, TIMEOUT, MUST) and `pitwall run` options; its stdout in $OUT, its exit
# status in $RC, its log in $TMP/NAME.err.
drive() {
  local name=$1
  shift
  local vars=()
  while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    vars+=("$1")
    shift
  done
  [ "${1:-}" = "--" ] && shift
  OUT=$(env "${vars[@]}" "$PITWALL" run "$SRC/tests/ble/laps.lua" --ble --scan-timeout 0.5 "$@" \
    2>"$TMP/$name.err")
  RC=$?
}
