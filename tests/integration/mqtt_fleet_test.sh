# A fleet across two pitwall processes and one private mosquitto (docs/mqtt.md): host A bridges
# two simulated cars, host B runs a race with them as remote cars (--cars 0 --remote-cars 2), then
# a mixed race with one local car besides. The race finishes with results for every car, host A's
# cars really drove (their own S/Speed/Actual on the tree), and they are stopped after each run,
# also after a script that never stops commanding, and while host B's loop is wedged (its
# watchdog).
source "$(dirname "$0")/mqtt_lib.sh"

count() { grep -cE -- "$2" "$1" 2>/dev/null || true; }
ALL="$TMP/all.sub"
RACE="$SRC/tests/integration/mqtt_race.lua"

# wait_last CAR TOPIC VALUE [SECONDS]: until the last CAR/TOPIC message seen has "value":VALUE.
wait_last() {
  local deadline=$((SECONDS + ${4:-5}))
  until [[ "$(last_value "$ALL" "Anki/Car/$1/$2")" == *"\"value\":$3}" ]]; do
    [ $SECONDS -ge $deadline ] && return 1
    sleep 0.02
  done
}

# cars_stopped NAME [FROM]: the last speed host A's cars were given is 0, and the bridge still
# runs. With FROM (a line of $ALL), the run's own 800 mm/s from that line on came before that 0.
cars_stopped() {
  local c
  for c in "${CARS[@]}"; do
    if [ -n "${2:-}" ]; then
      local deadline=$((SECONDS + 10))
      until tail -n +"$2" "$ALL" | grep -E "^Anki/Car/$c/S/Speed/Desired .*\"value\":800}" > /dev/null; do
        [ $SECONDS -ge $deadline ] && { fail "$1: $c never got the script's 800 mm/s"; break; }
        sleep 0.02
      done
    fi
    wait_last "$c" S/Speed/Desired 0 && echo "ok: $1: $c was stopped at the end (S/Speed/Desired 0)" ||
      fail "$1: last S/Speed/Desired of $c: $(last_value "$ALL" "Anki/Car/$c/S/Speed/Desired")"
  done
  kill -0 "$BRIDGE" 2>/dev/null && echo "ok: $1: host A's bridge still runs" || fail "$1: the bridge exited"
}

# after_run NAME: what every polite run must leave behind: host A's cars stopped and standing
# (the simulated car reports its actual speed when it is commanded: the race's own stop and the
# end of the run's stop find it standing), no error.
after_run() {
  local c
  cars_stopped "$1"
  for c in "${CARS[@]}"; do
    wait_last "$c" S/Speed/Actual 0 10 && echo "ok: $1: $c came to a halt (S/Speed/Actual 0)" ||
      fail "$1: last S/Speed/Actual of $c: $(last_value "$ALL" "Anki/Car/$c/S/Speed/Actual")"
  done
  check "$1: no intent of host B was refused" 0 "$(count "$ALL" '^Anki/Host/hostA/S/IntentError ')"
}

broker_config anonymous
start_broker
subscribe all 'Anki/#'
spawn bridge $PITWALL bridge --mqtt "$MQTT_URL" --host-id hostA --cars 2
BRIDGE=$LAST_PID
wait_for "$TMP/bridge.err" "bridging 2 cars as host hostA" ||
  { fail "host A's bridge did not start: $(cat "$TMP/bridge.err")"; finish; }
wait_for "$ALL" '^Anki/Host/hostA/S/Cars \["hostA-sim-[0-9a-f]+","hostA-sim-[0-9a-f]+"\]' 30 ||
  { fail "no S/Cars from host A"; finish; }
CARS=($(grep -m1 '^Anki/Host/hostA/S/Cars ' "$ALL" | grep -oE 'hostA-sim-[0-9a-f]+'))

# ---- host B: a race with host A's two cars ----
LAPS=1 timeout 60 $PITWALL run "$RACE" --cars 0 --mqtt "$MQTT_URL" --remote-cars 2 \
  >"$TMP/race.out" 2>"$TMP/race.err"
check "remote race: exit status" 0 "$?"
out=$(cat "$TMP/race.out")
contains "remote race: two remote cars" "Race: 2 cars" "$out"
contains "remote race: the remote cars are named" "2 remote cars through $MQTT_URL" "$(cat "$TMP/race.err")"
check "remote race: both cars finished the lap" 2 "$(grep -cE '^result [12] .* laps=1 finished=true' <<<"$out")"
contains "remote race: the results table" "POS  CAR" "$out"
contains "remote race: a winner" "Winner: " "$out"
for c in "${CARS[@]}"; do
  grep -qE "^Anki/Car/$c/S/Speed/Actual .*\"value\":[1-9][0-9]*}" "$ALL" &&
    echo "ok: remote race: host A's $c drove (S/Speed/Actual > 0)" || fail "remote race: $c never moved"
  grep -qE "^Anki/Car/$c/E/track_piece_id " "$ALL" &&
    echo "ok: remote race: $c published its pieces" || fail "remote race: no E/track_piece_id for $c"
  grep -qE "^Anki/Car/$c/I \{\"(speed|type)\":" "$ALL" &&
    echo "ok: remote race: host B drove $c through intents" || fail "remote race: no intent for $c"
done
after_run "remote race"

# ---- host B: a mixed race, one local simulated car and host A's two ----
moved_before=$(count "$ALL" "^Anki/Car/${CARS[0]}/S/Speed/Actual .*\"value\":[1-9]")
LAPS=1 timeout 60 $PITWALL run "$RACE" --cars 1 --mqtt "$MQTT_URL" --remote-cars 2 \
  >"$TMP/mixed.out" 2>"$TMP/mixed.err"
check "mixed race: exit status" 0 "$?"
out=$(cat "$TMP/mixed.out")
contains "mixed race: three cars" "Race: 3 cars" "$out"
check "mixed race: every car finished the lap" 3 "$(grep -cE '^result [123] .* laps=1 finished=true' <<<"$out")"
contains "mixed race: a winner" "Winner: " "$out"
[ "$(count "$ALL" "^Anki/Car/${CARS[0]}/S/Speed/Actual .*\"value\":[1-9]")" -gt "$moved_before" ] &&
  echo "ok: mixed race: host A's cars drove again" || fail "mixed race: host A's car did not move"
after_run "mixed race"

# ---- host B: a script that never stops commanding (tests/integration/nagging.lua), ended by
# --duration, os.exit, a dying main chunk and Ctrl-C: the stop is the last speed host A's cars
# get, however many intents were in flight.
while read -r mode status options; do
  from=$(wc -l <"$ALL")
  MODE=$mode timeout 60 $PITWALL run "$SRC/tests/integration/nagging.lua" --cars 0 \
    --mqtt "$MQTT_URL" --remote-cars 2 $options </dev/null >"$TMP/nag.out" 2>"$TMP/nag.err"
  check "nagging script ($mode): exit status" "$status" "$?"
  cars_stopped "nagging script ($mode)" "$from"
done <<'MODES'
none 0 --duration 2
exit 3
error 1
MODES
# nag_bg NAME MODE: host B's nagging script in the background, its stdout on fd 4 (run_fifo)
nag_bg() {
  run_fifo "$1" env MODE="$2" $PITWALL run "$SRC/tests/integration/nagging.lua" --cars 0 \
    --mqtt "$MQTT_URL" --remote-cars 2
}
from=$(wc -l <"$ALL")
nag_bg "nagging script (Ctrl-C)" none
kill -INT $RUN_PID
cat <&4 >/dev/null 2>&1 &
wait $RUN_PID
check "nagging script (Ctrl-C): exit status" 130 "$?"
exec 4<&-
cars_stopped "nagging script (Ctrl-C)" "$from"

# ---- host B's loop wedged in C code (a pattern that backtracks for hours): its watchdog
# publishes the stop intents on a connection of its own; host A's cars stop while B is stuck.
from=$(wc -l <"$ALL")
nag_bg wedged-host-B wedge
expect_wedged wedged-host-B
contains "wedged host B: stderr says the watchdog stopped both cars" \
  "the watchdog sent 2 cars its stop" "$(cat "$TMP/wedged-host-B.err")"
cars_stopped "wedged host B" "$from"  # while host B is still wedged
end_fifo

kill -TERM "$BRIDGE"
wait "$BRIDGE"
check "host A's bridge ends on SIGTERM" 130 "$?"
finish
