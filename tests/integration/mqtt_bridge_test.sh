# pitwall bridge as a user runs it, against a private mosquitto (docs/mqtt.md, mqtt-topics.md):
# the simulated cars' events and retained status on the seed's topic tree, every intent type sent
# with mosquitto_pub and its effect, malformed intents answered on S/IntentError, --read-only,
# the last will after kill -9, a broker restart, and a clean Ctrl-C.
source "$(dirname "$0")/mqtt_lib.sh"

# count FILE PATTERN: lines of FILE matching PATTERN (grep -E)
count() { grep -cE -- "$2" "$1" 2>/dev/null || true; }

# wait_count FILE PATTERN N [SECONDS]: until FILE has at least N lines matching PATTERN.
wait_count() {
  local deadline=$((SECONDS + ${4:-10}))
  until [ "$(count "$1" "$2")" -ge "$3" ]; do
    [ $SECONDS -ge $deadline ] && return 1
    sleep 0.02
  done
}

ALL="$TMP/all.sub"
# errors HOST: how many IntentErrors host HOST published so far
errors() { count "$ALL" "^Anki/Host/$1/S/IntentError "; }

broker_config anonymous
start_broker
subscribe all 'Anki/#'
# A retained intent left on the broker before the bridge starts: the bridge receives it flagged
# retained when it subscribes, and refuses it instead of running an old command.
pub "Anki/Host/pit1/I" '{"type":"speed","speed":100,"acceleration":1000}' -r

spawn bridge $PITWALL bridge --mqtt "$MQTT_URL" --host-id pit1 --cars 2 --mqtt-client-id bridge-pit1
BRIDGE=$LAST_PID
wait_for "$TMP/bridge.err" "bridging 2 cars as host pit1 on $MQTT_URL" ||
  { fail "the bridge did not start: $(cat "$TMP/bridge.err")"; finish; }
wait_for "$ALL" '^Anki/Host/pit1/S/Cars \["pit1-sim-[0-9a-f]+","pit1-sim-[0-9a-f]+"\]' 30 ||
  { fail "no S/Cars with two cars: $(grep Host "$ALL")"; finish; }
CARS=($(grep -m1 '^Anki/Host/pit1/S/Cars ' "$ALL" | grep -oE 'pit1-sim-[0-9a-f]+'))
C1=${CARS[0]}
C2=${CARS[1]}
echo "ok: the bridge publishes its cars: $C1 $C2"
wait_for "$ALL" '^Anki/Host/pit1/S/IntentError .*"topic":"Anki/Host/pit1/I".*retained intents are not executed' 5 &&
  echo "ok: the retained intent found on the broker is refused" || fail "no IntentError for the retained intent"
check "the retained intent was not executed" 0 "$(count "$ALL" '/S/Speed/Desired .*"value":100}')"
BASE_ERRORS=$(errors pit1) # that refusal
for c in $C1 $C2; do
  wait_for "$ALL" "^Anki/Host/pit1/E/CarDiscovered .*\"Car\":\"$c\"" 5 &&
    echo "ok: E/CarDiscovered for $c" || fail "no E/CarDiscovered for $c"
done

# ---- (b) the retained status, as a subscriber that comes later sees it ----
late=$(retained 'Anki/+/+/S/#')
contains "late subscriber: HostStatus true" 'Anki/Host/pit1/S/HostStatus {"value":true}' "$late"
contains "late subscriber: S/Cars" "Anki/Host/pit1/S/Cars [" "$late"
contains "late subscriber: S/Cars names both cars" "[\"$C1\",\"$C2\"]" "$late"
for c in $C1 $C2; do
  contains "late subscriber: $c Information" "Anki/Car/$c/S/Information {\"address\":\"sim:" "$late"
  contains "late subscriber: $c online" "Anki/Car/$c/S/CarStatus" "$(grep '"online":true' <<<"$late")"
done

# ---- (a) a race's events: a speed intent to one car, then to the host, then to every car ----
pub "Anki/Car/$C1/I" '{"type":"speed","speed":600,"acceleration":2000}'
wait_for "$ALL" "^Anki/Car/$C1/S/Speed/Desired .*\"value\":600}" 5 &&
  echo "ok: a single-car speed intent sets S/Speed/Desired" || fail "no Speed/Desired 600 for $C1"
for e in E/speed E/track_piece_id E/track_location_id E/frame E/lane/offset/actual; do
  wait_for "$ALL" "^Anki/Car/$C1/$e \{\"timestamp\":[0-9]+,\"value\":" 5 &&
    echo "ok: $C1 publishes $e" || fail "no $e for $C1"
done
wait_for "$ALL" "^Anki/Car/$C1/S/Speed/Actual .*\"value\":[1-9][0-9]*}" 5 &&
  echo "ok: $C1 drives (S/Speed/Actual > 0)" || fail "no Speed/Actual > 0 for $C1"
check "only the addressed car got the intent" 0 "$(count "$ALL" "^Anki/Car/$C2/S/Speed/Desired .*\"value\":600}")"
pub "Anki/Host/pit1/I" '{"type":"speed","speed":500,"acceleration":2000}'
for c in $C1 $C2; do
  wait_for "$ALL" "^Anki/Car/$c/S/Speed/Desired .*\"value\":500}" 5 &&
    echo "ok: a host intent reaches $c" || fail "no Speed/Desired 500 for $c"
done
pub "Anki/Car/all/I" '{"type":"speed","speed":700,"acceleration":2000}'
for c in $C1 $C2; do
  wait_for "$ALL" "^Anki/Car/$c/S/Speed/Desired .*\"value\":700}" 5 &&
    echo "ok: an all-cars intent reaches $c" || fail "no Speed/Desired 700 for $c"
  wait_for "$ALL" "^Anki/Car/$c/E/track_piece_id " 5 && wait_for "$ALL" "^Anki/Car/$c/E/frame [{]" 5 &&
    echo "ok: $c publishes its events" || fail "no events for $c"
done

# ---- (d) every intent type and its effect on the tree ----
pub "Anki/Car/$C1/I" '{"type":"lane","offset":40}'
wait_for "$ALL" "^Anki/Car/$C1/S/Lane/Desired .*\"value\":40.0}" 5 &&
  echo "ok: lane intent sets S/Lane/Desired" || fail "no Lane/Desired 40 for $C1"
wait_for "$ALL" "^Anki/Car/$C1/S/Lane/Actual .*\"value\":40.0}" 10 &&
  echo "ok: the car reaches the lane (S/Lane/Actual)" || fail "no Lane/Actual 40 for $C1"
# a U-turn: the car now faces the other way, so the same lane is -40 mm from its point of view
pub "Anki/Car/$C1/I" '{"type":"turn","turnType":3,"trigger":0}'
wait_for "$ALL" "^Anki/Car/$C1/S/Lane/Actual .*\"value\":-40.0}" 5 &&
  echo "ok: a U-turn intent turns the car (S/Lane/Actual flips to -40)" || fail "no U-turn seen"
for what in "battery S/BatteryLevel" "version S/Version"; do
  set -- $what
  before=$(count "$ALL" "^Anki/Car/$C2/$2 ")
  pub "Anki/Car/$C2/I" "{\"type\":\"$1\"}"
  wait_count "$ALL" "^Anki/Car/$C2/$2 \{\"timestamp\":[0-9]+,\"value\":[0-9]+}" $((before + 1)) 5 &&
    echo "ok: $1 intent answered on $2" || fail "no new $2 for $C2"
done
pub "Anki/Car/$C2/I" '{"type":"ping"}'
wait_for "$ALL" "^Anki/Car/$C2/S/PingResponse \{\"timestamp\":[0-9]+,\"rtt_ms\":[0-9.]+}" 5 &&
  echo "ok: ping intent answered with a round-trip time" || fail "no PingResponse for $C2"
# message: any controller→car frame; set-lights changes nothing on the tree and is no error,
# a set-speed frame shows as S/Speed/Desired
pub "Anki/Car/$C2/I" '{"type":"message","frame":"021d44"}'
pub "Anki/Car/$C2/I" '{"type":"message","frame":"06242c01e80300"}'
wait_for "$ALL" "^Anki/Car/$C2/S/Speed/Desired .*\"value\":300}" 5 &&
  echo "ok: a message intent's set-speed frame reaches the car" || fail "no Speed/Desired 300 for $C2"
check "the set-lights message is no error" "$BASE_ERRORS" "$(errors pit1)"
pub "Anki/Host/pit1/I/connection" '{"connecting":false}'
for c in $C1 $C2; do
  wait_for "$ALL" "^Anki/Car/$c/S/CarStatus .*\"online\":false" 5 &&
    echo "ok: connection false: $c offline" || fail "connection false: $c still online"
done
wait_for "$ALL" '^Anki/Host/pit1/S/Cars \[\]$' 5 &&
  echo "ok: connection false: S/Cars empty" || fail "connection false: S/Cars not emptied"
online_before=$(count "$ALL" "^Anki/Car/$C1/S/CarStatus .*\"online\":true")
pub "Anki/Host/pit1/I/connection" '{"connecting":true}'
wait_count "$ALL" "^Anki/Car/$C1/S/CarStatus .*\"online\":true" $((online_before + 1)) 5 &&
  echo "ok: connection true: the car is back online" || fail "connection true: $C1 not online"
wait_count "$ALL" "^Anki/Host/pit1/S/Cars \[\"$C1\",\"$C2\"\]$" 2 5 &&
  echo "ok: connection true: S/Cars lists both cars again" || fail "connection true: S/Cars"
pub "Anki/Car/$C1/I" '{"type":"speed","speed":650,"acceleration":2000}'
wait_for "$ALL" "^Anki/Car/$C1/S/Speed/Desired .*\"value\":650}" 5 &&
  echo "ok: a reconnected car takes intents" || fail "no Speed/Desired 650 after reconnecting"

# ---- (e) malformed intents: one IntentError each, nothing sent, the bridge carries on ----
desired_before=$(count "$ALL" "/S/Speed/Desired ")
E="^Anki/Host/pit1/S/IntentError "
# reject NAME TOPIC PAYLOAD EXPECTED [mosquitto_pub options…]
reject() {
  local name=$1 topic=$2 payload=$3 expected=$4 n
  shift 4
  n=$(errors pit1)
  pub "$topic" "$payload" "$@"
  if wait_count "$ALL" "$E" $((n + 1)) 5; then
    contains "$name: the error says why" "$expected" "$(grep -E "$E" "$ALL" | tail -1)"
    contains "$name: the error names the topic" "\"topic\":\"$topic\"" "$(grep -E "$E" "$ALL" | tail -1)"
  else
    fail "$name: no IntentError"
  fi
}
reject "bad JSON" "Anki/Car/$C1/I" '{"type":"speed",' "payload is not JSON"
reject "unknown type" "Anki/Car/all/I" '{"type":"fly"}' 'unknown intent type \"fly\"'
reject "speed out of range" "Anki/Car/$C1/I" '{"type":"speed","speed":2000,"acceleration":1000}' \
  "speed 2000 mm/s is out of range 0..1500 mm/s"
reject "unknown car" "Anki/Car/ffffffffffff/I" '{"type":"ping"}' 'unknown car \"ffffffffffff\"'
reject "a car's message in a frame" "Anki/Car/$C1/I" '{"type":"message","frame":"0117"}' "which a car sends"
# an empty payload is how MQTT clears a retained message (the one above): not an intent, no error
mosquitto_pub -h 127.0.0.1 -p "$MQTT_PORT" -q 1 -t "Anki/Host/pit1/I" -r -n
# one ping after the errors: its answer shows every intent before it was handled
pings=$(($(count "$ALL" "^Anki/Car/$C1/S/PingResponse ") + 1))
pub "Anki/Car/$C1/I" '{"type":"ping"}'
wait_count "$ALL" "^Anki/Car/$C1/S/PingResponse " $pings 5 || fail "no ping answer after the errors"
check "one IntentError per malformed intent (and the retained one)" 6 "$(errors pit1)"
check "the retained intent was not executed" 0 "$(count "$ALL" "^Anki/Car/$C1/S/Speed/Desired .*\"value\":100}")"
check "no S/Speed/Desired from a malformed intent" "$desired_before" "$(count "$ALL" "/S/Speed/Desired ")"
kill -0 "$BRIDGE" 2>/dev/null && echo "ok: the bridge still runs" || fail "the bridge exited"

# ---- (g) the broker restarts (retained state lost): the bridge reconnects and republishes ----
stop_broker
wait_for "$TMP/bridge.err" "lost the connection to the MQTT broker at $MQTT_URL" 5 &&
  echo "ok: the bridge notices the broker is gone" || fail "no loss logged: $(tail -3 "$TMP/bridge.err")"
start_broker
subscribe all2 'Anki/#'
ALL2="$TMP/all2.sub"
wait_for "$TMP/all2.sub" '^Anki/Host/pit1/S/HostStatus \{"value":true\}' 15 &&
  echo "ok: the bridge reconnected" || fail "no HostStatus after the broker restart: $(tail -3 "$TMP/bridge.err")"
late=$(retained 'Anki/+/+/S/#')
contains "after the restart: HostStatus true again" 'Anki/Host/pit1/S/HostStatus {"value":true}' "$late"
contains "after the restart: S/Cars again" "Anki/Host/pit1/S/Cars [" "$(grep "\[\"$C1\",\"$C2\"\]" <<<"$late")"
contains "after the restart: the car's Information again" "Anki/Car/$C1/S/Information " "$late"
pub "Anki/Car/$C2/I" '{"type":"speed","speed":450,"acceleration":2000}'
wait_for "$TMP/all2.sub" "^Anki/Car/$C2/S/Speed/Desired .*\"value\":450}" 5 &&
  echo "ok: intents work after the restart" || fail "no intent after the restart"

# ---- (h) a clean Ctrl-C: cars stopped and offline, HostStatus false, a clean DISCONNECT ----
kill -INT "$BRIDGE"
wait "$BRIDGE"
check "Ctrl-C exit status" 130 "$?"
late=$(retained 'Anki/+/+/S/#')
contains "Ctrl-C: HostStatus false" 'Anki/Host/pit1/S/HostStatus {"value":false}' "$late"
contains "Ctrl-C: S/Cars empty" 'S/Cars []' "$(grep '^Anki/Host/pit1/S/Cars ' <<<"$late")"
for c in $C1 $C2; do
  contains "Ctrl-C: $c offline" '"online":false' "$(grep "^Anki/Car/$c/S/CarStatus " <<<"$late")"
  contains "Ctrl-C: $c stopped" '"value":0}' "$(grep "^Anki/Car/$c/S/Speed/Desired " <<<"$late")"
done
# a clean goodbye is a DISCONNECT the broker saw (not a dropped socket answered by the will)
log=$(grep "bridge-pit1" "$BROKER_DIR/mosquitto.log" | tail -1)
contains "Ctrl-C: the broker saw a clean disconnect" "Client bridge-pit1 disconnected." "$log"

# ---- (f) --read-only publishes and executes nothing; (c) its last will after kill -9 ----
# (after pit1 is gone: a simulated car's id is the same in every bridge)
seen=$(wc -l <"$ALL2")
since() { tail -n +$((seen + 1)) "$ALL2"; }
spawn ro $PITWALL bridge --mqtt "$MQTT_URL" --host-id ro --cars 1 --read-only --mqtt-client-id bridge-ro
RO=$LAST_PID
wait_for "$TMP/ro.err" "bridging 1 car as host ro" || fail "the read-only bridge did not start: $(cat "$TMP/ro.err")"
wait_for "$ALL2" '^Anki/Host/ro/S/Cars \["ro-sim-' 30 || fail "no S/Cars from the read-only bridge"
RC=$(grep -m1 '^Anki/Host/ro/S/Cars ' "$ALL2" | grep -oE 'ro-sim-[0-9a-f]+')
contains "the read-only bridge says so" "publishing as host ro (read-only)" "$(cat "$TMP/ro.err")"
pub "Anki/Car/$RC/I" '{"type":"speed","speed":800,"acceleration":2000}'
pub "Anki/Host/ro/I" '{"type":"speed","speed":800,"acceleration":2000}'
pub "Anki/Car/all/I" '{"type":"speed","speed":800,"acceleration":2000}'
# the broker saw it subscribe to nothing (pit1, for comparison, subscribed to the intents)
contains "pit1 subscribed to the intents" "bridge-pit1 1 Anki/Car/+/I" "$(cat "$BROKER_DIR/mosquitto.log")"
check "read-only: no subscription at all" "" "$(grep -E 'bridge-ro [0-2] ' "$BROKER_DIR/mosquitto.log")"
# nothing can be awaited from a bridge that ignores intents: give it a moment to misbehave
sleep 0.5
check "read-only: no S/Speed/Desired" "" "$(since | grep "^Anki/Car/$RC/S/Speed/Desired ")"
check "read-only: no IntentError" "" "$(since | grep '^Anki/Host/ro/S/IntentError ')"
check "read-only: the car stays still" "" "$(since | grep -E "^Anki/Car/$RC/S/Speed/Actual .*\"value\":[1-9]")"
kill -9 "$RO"
wait "$RO" 2>/dev/null
wait_for "$ALL2" '^Anki/Host/ro/S/HostStatus \{"value":false\}' 5 &&
  echo "ok: kill -9: the broker publishes the last will" || fail "no will after kill -9"
contains "kill -9: a late subscriber sees HostStatus false" 'Anki/Host/ro/S/HostStatus {"value":false}' \
  "$(retained 'Anki/Host/ro/S/HostStatus')"

finish
