#!/usr/bin/env bash
# A spectator through the broker (docs/view.md "Spectators"): a bridge publishes two simulated
# cars on a private mosquitto, an intent makes them drive, and `pitwall view --mqtt` in another
# process shows them: /api/state lists both bridged cars, placed on the drawn track and moving,
# with their laps counted. The spectator is read-only: the broker's log shows no PUBLISH from
# it, not even when it ends (no sync marker, no intent, no stop).
source "$(dirname "$0")/mqtt_lib.sh"

broker_config anonymous
echo "log_type debug" >>"$BROKER_DIR/mosquitto.conf"  # every PUBLISH received, with its client
start_broker

"$PITWALL" bridge --mqtt "$MQTT_URL" --host-id pitA --cars 2 --mqtt-client-id bridgeA \
  >"$TMP/bridge.out" 2>"$TMP/bridge.err" &
PIDS+=($!)
wait_for "$TMP/bridge.err" "bridging 2 cars" 20 || { fail "the bridge did not start"; cat "$TMP/bridge.err"; finish; }

"$PITWALL" view --mqtt "$MQTT_URL" --mqtt-client-id spectator --view 127.0.0.1:0 \
  >"$TMP/view.out" 2>"$TMP/view.err" &
spectator=$!
PIDS+=($spectator)
wait_for "$TMP/view.err" '^view: http://127\.0\.0\.1:[0-9]+/' 20 ||
  { fail "no view URL from pitwall view"; cat "$TMP/view.err"; finish; }
url=$(grep -oE 'http://127\.0\.0\.1:[0-9]+/' "$TMP/view.err" | head -1)
echo "ok: spectator's view at $url"

# Drive the bridged cars (an intent to every car of host pitA).
mosquitto_pub -h 127.0.0.1 -p "$MQTT_PORT" -q 1 -t "Anki/Host/pitA/I" \
  -m '{"type":"speed","speed":800,"acceleration":2000}'

# The spectator's state: both cars, remote, placed on the oval, moving; a lap counted. Polled
# (the state of another process), bounded.
result=$(timeout 60 python3 - "$url" <<'PY'
import json, sys, time, urllib.request
url = sys.argv[1] + "api/state"
deadline = time.time() + 50
last = None
while time.time() < deadline:
    s = json.load(urllib.request.urlopen(url, timeout=5))
    cars = s["cars"]
    placed = [c for c in cars if c["x"] is not None and c["connected"] and c["speed"] > 0]
    if s["source"] == "mqtt" and len(cars) == 2 and len(placed) == 2 and \
            all(c["lap"] >= 1 for c in cars):
        print("ok", len(cars), sorted(c["name"] for c in cars), s["track"]["name"])
        sys.exit(0)
    last = [(c["name"], c["connected"], c["speed"], c["x"], c["lap"]) for c in cars]
    time.sleep(0.2)
print("timeout", last)
PY
)
contains "the spectator shows both bridged cars, placed and lapping" "ok 2" "$result"
echo "  ($result)"

kill -INT "$spectator"
wait "$spectator"
check "the spectator ends on Ctrl-C" 130 "$?"
published=$(grep -c "Received PUBLISH from spectator" "$BROKER_DIR/mosquitto.log")
check "the spectator published nothing" 0 "$published"
grep -q "Received PUBLISH from bridgeA" "$BROKER_DIR/mosquitto.log" &&
  echo "ok: (the broker's log does show the bridge's publications)" ||
  fail "the broker's log shows no PUBLISH at all: the check above proves nothing"
finish
