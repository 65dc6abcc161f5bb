# Remote cars (pitwall run --mqtt) from a bridge that publishes only what the seed's controller
# publishes (tests/integration/fake_controller.py: no E/frame, its forms and topics): the car
# joins, its position, ping, battery and version arrive through the controller's E/Messages
# events, commands reach it as the controller's intents, and a command it has no intent for is
# refused in the script with the reason (docs/mqtt.md "Remote cars").
source "$(dirname "$0")/mqtt_lib.sh"

/usr/bin/python3 -c 'import paho.mqtt' 2>/dev/null ||
  { fail "python3-paho-mqtt is not installed (./dev test installs it)"; finish; }

CAR=d205effe02cb
broker_config anonymous
start_broker
subscribe all 'Anki/#'
ALL="$TMP/all.sub"
/usr/bin/python3 "$SRC/tests/integration/fake_controller.py" "$MQTT_PORT" "$CAR" \
  >"$TMP/controller.out" 2>"$TMP/controller.err" &
CONTROLLER=$!
PIDS+=("$CONTROLLER")
wait_for "$TMP/controller.out" "^ready" 10 ||
  { fail "the fake controller did not start: $(cat "$TMP/controller.err")"; finish; }
# as the track editor does: ask the controller to scan and connect
pub "Anki/Host/host/I" '{"connecting":true}'
wait_for "$ALL" "^Anki/Host/host/S/Cars \[\"$CAR\"\]" 10 ||
  { fail "the controller did not list its car"; finish; }

timeout 60 $PITWALL run "$SRC/tests/integration/seed_remote.lua" --cars 0 --mqtt "$MQTT_URL" \
  --remote-cars 1 >"$TMP/run.out" 2>"$TMP/run.err"
check "the script's exit status" 0 "$?"
out=$(cat "$TMP/run.out")
cat "$TMP/run.out"
contains "the controller's car joined as a remote car" "check car car 1 (skull) Skull mqtt:$CAR" "$out"
for step in speed lane ping battery version positions uturn stopped; do
  grep -qE "^check $step true" <<<"$out" && echo "ok: $step" ||
    fail "$step: $(grep "^check $step" <<<"$out")"
done
contains "battery and version from E/Messages" "check battery true 3950" "$out"
contains "lights refused with the reason" "check lights false" "$out"
contains "the script's error names the controller" "set-lights was not sent: car $CAR is bridged by the seed's controller (its S/Information names no pitwall bridge), which has no intent for set-lights" "$out"

intents=$(grep '^intent ' "$TMP/controller.out")
contains "speed went as the controller's form" "intent Anki/Car/$CAR/I {\"speed\":600,\"acceleration\":2000}" "$intents"
contains "lane went with the offset the controller reads" "intent Anki/Car/$CAR/I {\"lane\":23.0,\"offset\":23.0" "$intents"
contains "the U-turn" "intent Anki/Car/$CAR/I {\"turn\":{\"type\":3,\"time\":0}}" "$intents"
for k in ping battery version; do
  contains "$k went as {\"$k\":true}" "intent Anki/Car/$CAR/I {\"$k\":true}" "$intents"
done
contains "the stop" "intent Anki/Car/$CAR/I {\"speed\":0," "$intents"
check "nothing in pitwall's own forms reached the controller" 0 "$(grep -c '/I {"type":' <<<"$intents")"
finish
