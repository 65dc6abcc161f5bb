# A client of the seed's controller (tests/integration/seed_client.py: its clients' payloads and
# topics, unchanged) against `pitwall bridge` on a private mosquitto, host id "host" as the
# controller's: connects the cars, drives them one by one and all at once, reads the car list,
# pings, and reads every event and status topic of seed 000 §4.4 (docs/mqtt-topics.md
# "Compatibility with the seed's controller").
source "$(dirname "$0")/mqtt_lib.sh"

/usr/bin/python3 -c 'import paho.mqtt' 2>/dev/null ||
  { fail "python3-paho-mqtt is not installed (./dev test installs it)"; finish; }

broker_config anonymous
start_broker
spawn bridge $PITWALL bridge --mqtt "$MQTT_URL" --host-id host --cars 2
BRIDGE=$LAST_PID
wait_for "$TMP/bridge.err" "bridging 2 cars as host host on $MQTT_URL" ||
  { fail "the bridge did not start: $(cat "$TMP/bridge.err")"; finish; }

/usr/bin/python3 "$SRC/tests/integration/seed_client.py" "$MQTT_PORT" >"$TMP/client.out" 2>&1
status=$?
cat "$TMP/client.out"
check "the seed's client: every check passed" 0 "$status"
grep -q "^ok: " "$TMP/client.out" || fail "the seed's client checked nothing"
kill -0 "$BRIDGE" 2>/dev/null && echo "ok: the bridge still runs" || fail "the bridge exited"
finish
