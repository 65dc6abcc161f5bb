# pitwall repl --ble (fake BlueZ, real D-Bus): the real cars are bound as `cars`, commands reach
# them, and leaving stops and disconnects them.
source "$(dirname "$0")/ble_lib.sh"
start_bus
start_fake --cars 2
out=$(printf '%s\n' '=#cars' '=cars[1].address' 'cars[1]:setSpeed(700)' \
  '=cars[2]:setSpeed(5000)' '=cars[1].targetSpeed' |
  "$PITWALL" repl --ble --scan-timeout 0.5 2>"$TMP/repl.err"); rc=$?
check "exit status: 1, since one chunk failed" 1 "$rc"
check "both cars bound" 2 "$(echo "$out" | sed -n 1p)"
check "cars[1] is the first car found" '"ble:E0:00:00:00:00:01"' "$(echo "$out" | sed -n 2p)"
check "a command reached the car" 700 "$(echo "$out" | sed -n 3p)"
contains "an out-of-range command is refused clearly" "0..1500" "$(cat "$TMP/repl.err")"
stop_fake
summary=$(cat "$TMP/fake.out")
contains "car 1 left stopped and disconnected" "E0:00:00:00:00:01 connected=false target=0" "$summary"
contains "car 2 left stopped and disconnected" "E0:00:00:00:00:02 connected=false target=0" "$summary"

err=$("$PITWALL" repl --ble --cars 2 2>&1 >/dev/null </dev/null); rc=$?
check "--ble with --cars is refused" 2 "$rc"
contains "and says why" "excludes" "$err"
finish
