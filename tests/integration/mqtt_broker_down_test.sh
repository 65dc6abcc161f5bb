# pitwall bridge started while its broker is down (docs/mqtt.md "A refused login"): it says it
# waits for the broker, with the reason, and not that it bridges; once a real mosquitto listens
# on that port it says "bridging" and publishes its cars.
source "$(dirname "$0")/mqtt_lib.sh"

broker_config anonymous # a free port: nobody listens on it yet
spawn bridge $PITWALL bridge --mqtt "$MQTT_URL" --host-id down1 --cars 2 --mqtt-client-id bridge-down1
BRIDGE=$LAST_PID
wait_for "$TMP/bridge.err" "waiting for the broker at $MQTT_URL \(.+\), retrying" 20 ||
  { fail "no line saying the bridge waits for the broker: $(cat "$TMP/bridge.err")"; finish; }
line=$(grep -m1 "waiting for the broker" "$TMP/bridge.err")
contains "the waiting line gives the reason" "(Connection refused)" "$line"
contains "the waiting line says what comes next" "the 2 cars are bridged once it accepts the connection" "$line"
check "no 'bridging' while the broker is down" 0 "$(grep -c "bridging" "$TMP/bridge.err")"
kill -0 "$BRIDGE" 2>/dev/null && echo "ok: the bridge keeps running without its broker" ||
  fail "the bridge ended without its broker: $(cat "$TMP/bridge.err")"

start_broker
wait_for "$TMP/bridge.err" "bridging 2 cars as host down1 on $MQTT_URL" 20 &&
  echo "ok: 'bridging' once the broker accepted the connection" ||
  { fail "no 'bridging' after the broker came up: $(cat "$TMP/bridge.err")"; finish; }
waiting=$(grep -n -m1 "waiting for the broker" "$TMP/bridge.err" | cut -d: -f1)
bridging=$(grep -n -m1 "bridging" "$TMP/bridge.err" | cut -d: -f1)
[ "$waiting" -lt "$bridging" ] && echo "ok: waiting first, bridging after" ||
  fail "the lines came in the wrong order: $(cat "$TMP/bridge.err")"
check "'bridging' is said once" 1 "$(grep -c "bridging" "$TMP/bridge.err")"
late=$(retained 'Anki/Host/down1/S/#')
contains "the bridge published its host status" 'Anki/Host/down1/S/HostStatus {"value":true}' "$late"
contains "and its cars" 'Anki/Host/down1/S/Cars ["down1-sim-' "$late"

kill -INT "$BRIDGE"
wait "$BRIDGE"
check "Ctrl-C: exit status" 130 "$?"
finish
