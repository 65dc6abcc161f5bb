# shellcheck shell=bash
# The central played by BlueZ's own bluetoothctl on hci1 (sourced by guest.sh, which provides
# say, fail, until_ok, $LOGS, $ADDR1). Proves what a BLE pitwall needs from the peripheral, with
# no pitwall code on the central side:
#   1. hci1 sees an advertisement carrying the Anki service UUID and manufacturer data (0xefbe,
#      model 8) and the name;
#   2. it connects and the services resolve;
#   3. subscribing to the read characteristic and writing a ping `01 16` to the write
#      characteristic brings a notification `01 17`;
#   4. after a disconnect the car advertises again: a second connection works the same way.
# bluetoothctl reads commands from a FIFO and writes to a log that `expect` searches.

BT_LOG=$LOGS/bluetoothctl.log
BT_MARK=0  # lines of the log before the last command sent: `expect` looks after them

bt() {
  BT_MARK=$(wc -l <"$BT_LOG")
  echo "$*" >&7
}
# The log since the last command, without colours and prompts.
bt_since() {
  tail -n +$((BT_MARK + 1)) "$BT_LOG" | sed -e 's/\x1b\[[0-9;]*m//g' -e 's/\r//g' \
    -e 's/\x01\|\x02//g'
}
bt_matches() { bt_since | grep -E -- "$BT_EXPECT" > /dev/null; }
# expect SECONDS REGEX WHAT: waits until the output since the last command matches.
expect() {
  BT_EXPECT=$2
  until_ok "$1" bt_matches || fail "bluetoothctl: no $3 within $1 s"
}
# The device's properties, once they include the advertisement's manufacturer data.
bt_info() {
  bt "info $1"
  sleep 0.2
  bt_since | grep ManufacturerData > /dev/null
}

central_tools() {
  local car=$1 service=be15beef-6186-407e-8381-0bd89c4d8df4
  local read_uuid=be15bee0-6186-407e-8381-0bd89c4d8df4
  local write_uuid=be15bee1-6186-407e-8381-0bd89c4d8df4
  mkfifo /tmp/bluetoothctl.in
  stdbuf -oL -eL bluetoothctl </tmp/bluetoothctl.in >"$BT_LOG" 2>&1 &
  local bt_pid=$!
  exec 7>/tmp/bluetoothctl.in

  bt "select $ADDR1"
  expect 5 "Controller $ADDR1" "controller $ADDR1 selected"
  bt "scan on"
  expect 20 "Device $car" "advertisement from $car"
  say "tools: hci1 sees $car advertising"
  until_ok 5 bt_info "$car" || fail "bluetoothctl shows no manufacturer data for $car: $(bt_since)"
  local info
  info=$(bt_since)
  grep -q "$service" <<< "$info" || fail "the advertisement has no Anki service UUID: $info"
  grep -q -i "Key: 0xefbe" <<< "$info" || fail "no manufacturer data 0xefbe: $info"
  grep -q "00 08" <<< "$info" || fail "the manufacturer data does not say model 8: $info"
  say "tools: service $service, manufacturer data 0xefbe (model 8): $(echo "$info" |
    grep -E 'Name:' | head -n1 | xargs)"
  bt "scan off"

  for round in 1 2; do
    bt "connect $car"
    expect 15 "Connection successful" "connection to $car (round $round)"
    expect 15 "ServicesResolved: yes" "resolved services (round $round)"
    say "tools: connected (round $round)"
    bt "menu gatt"
    bt "list-attributes $car"
    expect 5 "$write_uuid" "write characteristic $write_uuid"
    local attrs read_path write_path
    attrs=$(bt_since)
    read_path=$(echo "$attrs" | grep -B1 "$read_uuid" | grep -o '/org/bluez/[^ ]*' | head -n1)
    write_path=$(echo "$attrs" | grep -B1 "$write_uuid" | grep -o '/org/bluez/[^ ]*' | head -n1)
    [ -n "$read_path" ] && [ -n "$write_path" ] || fail "characteristics not found: $attrs"
    # The notified values as the central's bluetoothd publishes them (bluetoothctl does not
    # always print a value that arrives while its own write is still being answered).
    dbus-monitor --system "type='signal',member='PropertiesChanged',path='$read_path'" \
      >"$LOGS/values.$round" 2>&1 &
    local monitor=$!
    bt "select-attribute $read_path"
    bt "notify on"
    expect 5 "Notify started" "subscription to $read_path"
    bt "select-attribute $write_path"
    local t0
    t0=$(date +%s%N)
    bt "write \"0x01 0x16\""
    until_ok 5 grep -q -x '  *01 17' "$LOGS/values.$round" ||
      fail "no notification 01 17 after the ping 01 16: $(cat "$LOGS/values.$round")"
    say "tools: ping 01 16 → notification 01 17 in $((($(date +%s%N) - t0) / 1000000)) ms"
    kill "$monitor"
    bt "back"
    [ "$round" = 2 ] && break  # the car's own shutdown ends the second link
    bt "disconnect $car"
    expect 10 "Connected: no|Successful disconnected" "disconnection (round $round)"
    say "tools: disconnected (round $round)"
  done
  bt "quit"
  exec 7>&-
  wait "$bt_pid"
  return 0
}
