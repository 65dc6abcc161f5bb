# Hostile MQTT input as a user's broker would carry it (docs/mqtt.md "Hostile input"): a running
# `pitwall bridge` and a `pitwall run --mqtt` reading its cars both get, with mosquitto_pub,
# numbers beyond a double, invalid UTF-8, JSON nested 100 000 deep, a 1 MB payload and binary
# garbage. Neither process dies, each refusal is short, and after every payload the bridge still
# obeys a valid intent and the reader still follows the cars.
source "$(dirname "$0")/mqtt_lib.sh"

ALL="$TMP/all.sub"
broker_config anonymous
start_broker
subscribe all 'Anki/#'
spawn bridge $PITWALL bridge --mqtt "$MQTT_URL" --host-id pit1 --cars 2
BRIDGE=$LAST_PID
wait_for "$ALL" '^Anki/Host/pit1/S/Cars \["pit1-sim-[0-9a-f]+","pit1-sim-[0-9a-f]+"\]' 10 ||
  { fail "the bridge did not publish its cars: $(cat "$TMP/bridge.err")"; finish; }
CARS=($(grep -m1 '^Anki/Host/pit1/S/Cars ' "$ALL" | grep -oE 'pit1-sim-[0-9a-f]+'))
C1=${CARS[0]}

# The hostile payloads, one file each.
H="$TMP/hostile"
mkdir -p "$H"
printf '{"type":"speed","speed":5e999,"acceleration":1000}' >"$H/huge-number"
printf '{"type":"lane","offset":1e400}' >"$H/huge-offset"
printf '{"type":"speed","speed":\xff\xfe,"acceleration":1000}' >"$H/invalid-utf8"
printf '{"type":"\xc3\x28","speed":600}' >"$H/invalid-utf8-string"
python3 -c "import sys; sys.stdout.write('[' * 100000 + ']' * 100000)" >"$H/deep-and-big"
python3 -c "import sys; sys.stdout.write('{\"type\":' + '[' * 30000 + ']' * 30000 + '}')" >"$H/deep"
python3 -c "import sys; sys.stdout.write('{\"type\":\"speed\",\"pad\":\"' + 'x' * 1048576 + '\"}')" >"$H/one-megabyte"
head -c 4096 /dev/urandom >"$H/garbage"

# pubfile TOPIC FILE: FILE's bytes as one message (QoS 1)
pubfile() {
  mosquitto_pub -h 127.0.0.1 -p "$MQTT_PORT" "${MQTT_CLIENT_ARGS[@]}" -q 1 -t "$1" -f "$2"
}

speed=300
obeys() {  # NAME: a valid intent after it is executed (S/Speed/Desired follows)
  speed=$((speed + 1))
  pub "Anki/Car/$C1/I" "{\"type\":\"speed\",\"speed\":$speed,\"acceleration\":1000}"
  wait_for "$ALL" "^Anki/Car/$C1/S/Speed/Desired .*\"value\":$speed}" 10 &&
    echo "ok: bridge: after $1, a valid intent is obeyed" || fail "bridge: after $1, the car did not obey"
}
for f in "$H"/*; do
  name=$(basename "$f")
  pubfile "Anki/Car/$C1/I" "$f"
  obeys "$name"
done
kill -0 "$BRIDGE" 2>/dev/null && echo "ok: the bridge survived every hostile intent" ||
  fail "the bridge died: $(tail -5 "$TMP/bridge.err")"
longest=$(grep -a '^Anki/Host/pit1/S/IntentError ' "$ALL" | awk '{print length($0)}' | sort -n | tail -1)
[ "${longest:-0}" -le 1200 ] && echo "ok: every IntentError is short (longest line $longest bytes)" ||
  fail "an IntentError line of $longest bytes"
contains "the huge number is named" "beyond the range of a double" "$(grep -a '^Anki/Host/pit1/S/IntentError ' "$ALL")"
contains "the deep nesting is named" "more than 64 deep" "$(grep -a '^Anki/Host/pit1/S/IntentError ' "$ALL")"
contains "the big payload is named" "65536" "$(grep -a '^Anki/Host/pit1/S/IntentError ' "$ALL")"

# The reading side: a run with the bridge's cars as remote cars, fed the same payloads on the
# topics it reads; it counts its cars' position events before and after them.
cat >"$TMP/reader.lua" <<'LUA'
local events = 0
for _, car in ipairs(pitwall.cars()) do
  car.onPosition = function() events = events + 1 end
  car:setSpeed(600)
end
print("reading")
io.stdout:flush()
pitwall.sleep(1)
local before = events
pitwall.sleep(3)
print(string.format("events before %d after %d", before, events - before))
pitwall.stop()
LUA
mkfifo "$TMP/reader.fifo"
$PITWALL run "$TMP/reader.lua" --cars 0 --mqtt "$MQTT_URL" --remote-cars 2 \
  >"$TMP/reader.fifo" 2>"$TMP/reader.err" &
READER=$!
exec 4<"$TMP/reader.fifo"
read -r -t 20 -u 4 line
check "the reader runs with the remote cars" "reading" "$line"
for f in "$H"/*; do
  for topic in "Anki/Host/pit1/S/Cars" "Anki/Host/pit1/S/HostStatus" "Anki/Car/$C1/E/frame" \
    "Anki/Car/$C1/S/CarStatus" "Anki/Host/evil/S/Cars"; do
    pubfile "$topic" "$f"
  done
done
read -r -t 20 -u 4 line
wait $READER
check "the reader ends as its script says" 0 $?
exec 4<&-
after=$(sed -n 's/.* after \([0-9]*\)$/\1/p' <<<"$line")
[ "${after:-0}" -gt 0 ] && echo "ok: the reader still follows the cars after the hostile payloads ($line)" ||
  fail "the reader lost its cars: [$line] $(tail -5 "$TMP/reader.err")"
kill -0 "$BRIDGE" 2>/dev/null && echo "ok: the bridge still runs" || fail "the bridge died"

finish
