# pitwall bridge --ble (fake BlueZ on a private bus, a private mosquitto): real cars found by a
# scan are published with their Bluetooth ids, intents drive them, the connection intent drops
# and reconnects them through BlueZ, and Ctrl-C leaves them stopped and disconnected.
source "$(dirname "$0")/ble_lib.sh"
source "$(dirname "$0")/mqtt_lib.sh"
trap 'cleanup_mqtt_processes; cleanup_ble' EXIT
cleanup_mqtt_processes() {
  local p
  for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null; done
  [ -n "$BROKER_PID" ] && kill -9 "$BROKER_PID" 2>/dev/null
}
count() { grep -cE -- "$2" "$1" 2>/dev/null || true; }
# wait_count FILE PATTERN N [SECONDS]: until FILE has at least N lines matching PATTERN.
wait_count() {
  local deadline=$((SECONDS + ${4:-10}))
  until [ "$(count "$1" "$2")" -ge "$3" ]; do
    [ $SECONDS -ge $deadline ] && return 1
    sleep 0.02
  done
}

start_bus
start_fake --cars 2
broker_config anonymous
start_broker
subscribe all 'Anki/#'
ALL="$TMP/all.sub"
C1=e00000000001
C2=e00000000002

spawn bridge "$PITWALL" bridge --ble --scan-timeout 0.5 --mqtt "$MQTT_URL" --host-id blue
BRIDGE=$LAST_PID
wait_for "$TMP/bridge.err" "bridging 2 cars as host blue" 15 ||
  { fail "the bridge did not start: $(cat "$TMP/bridge.err")"; finish; }
wait_for "$ALL" "^Anki/Host/blue/S/Cars \[\"$C1\",\"$C2\"\]" 5 &&
  echo "ok: the cars are published under their Bluetooth ids" ||
  fail "no S/Cars with $C1 and $C2: $(grep '/S/Cars' "$ALL")"
contains "S/Information has the car's address" "\"address\":\"E0:00:00:00:00:01\"" \
  "$(grep "^Anki/Car/$C1/S/Information " "$ALL")"

pub "Anki/Car/$C1/I" '{"type":"speed","speed":600,"acceleration":2000}'
wait_for "$ALL" "^Anki/Car/$C1/S/Speed/Desired .*\"value\":600}" 5 &&
  echo "ok: a speed intent reaches the car" || fail "no S/Speed/Desired 600"
wait_for "$ALL" "^Anki/Car/$C1/S/Speed/Actual .*\"value\":[1-9][0-9]*}" 5 &&
  echo "ok: the car drives (its own speed reports)" || fail "no S/Speed/Actual > 0"
wait_for "$ALL" "^Anki/Car/$C1/E/track_piece_id " 10 &&
  echo "ok: its position events are published" || fail "no E/track_piece_id"

# connection false: every car disconnected through BlueZ; true: found and connected again
pub "Anki/Host/blue/I/connection" '{"connecting":false}'
for c in $C1 $C2; do
  wait_for "$ALL" "^Anki/Car/$c/S/CarStatus .*\"online\":false" 10 &&
    echo "ok: connection false: $c offline" || fail "connection false: $c still online"
done
wait_for "$ALL" '^Anki/Host/blue/S/Cars \[\]$' 5 &&
  echo "ok: connection false: no cars listed" || fail "connection false: S/Cars not emptied"
both="^Anki/Host/blue/S/Cars \[\"$C1\",\"$C2\"\]$"
listed=$(count "$ALL" "$both")
pub "Anki/Host/blue/I/connection" '{"connecting":true}'
wait_count "$ALL" "$both" $((listed + 1)) 15 &&
  echo "ok: connection true: both cars connected again" ||
  fail "connection true: $(grep '/S/Cars' "$ALL" | tail -2)"
pub "Anki/Car/$C2/I" '{"type":"ping"}'
wait_for "$ALL" "^Anki/Car/$C2/S/PingResponse .*\"rtt_ms\":[0-9.]+}" 5 &&
  echo "ok: a reconnected car answers a ping" || fail "no PingResponse from $C2"

kill -INT "$BRIDGE"
wait "$BRIDGE"
check "Ctrl-C: exit status 130" 130 "$?"
wait_for "$ALL" '^Anki/Host/blue/S/HostStatus \{"value":false\}' 5 &&
  echo "ok: Ctrl-C: HostStatus false" || fail "no HostStatus false"
stop_fake
summary=$(cat "$TMP/fake.out")
contains "car 1 left stopped and disconnected" "E0:00:00:00:00:01 connected=false target=0" "$summary"
contains "car 2 left stopped and disconnected" "E0:00:00:00:00:02 connected=false target=0" "$summary"
finish
