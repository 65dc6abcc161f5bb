# Cars that misbehave over Bluetooth LE, as a user's race sees them (fake BlueZ, real D-Bus):
# a link that drops mid-race comes back by itself with SDK mode restored, a command to a car that
# is away fails with a clear error, a car that vanishes is reported and the race goes on, a car
# that refuses connections is retried with backoff.
source "$(dirname "$0")/ble_lib.sh"
start_bus
A1=E0:00:00:00:00:01
A2=E0:00:00:00:00:02

# A dropped link mid-race
start_fake --cars 2 --drop $A1@1.5
drive drop CROSSINGS=3 SPEED=1200 TIMEOUT=40
check "drop: the race finishes" 0 "$RC"
line=$(echo "$OUT" | grep "^car ble:$A1 ")
check "drop: the script saw the car go" 1 "$(field disconnects "$line")"
check "drop: and come back (onConnect)" 1 "$(field connects "$line")"
check "drop: a command while it was away failed clearly" 1 "$(field refusedWhileDown "$line")"
check "drop: it lapped after coming back (SDK mode restored)" 3 "$(field laps "$line")"
contains "drop: the log says it reconnects" "reconnecting in" "$(cat "$TMP/drop.err")"
stop_fake
contains "drop: the fake saw two connections" "$A1 connected=false target=0 connects=2" \
  "$(cat "$TMP/fake.out")"

# A car that vanishes for good: reported, never called again, the other car races on
start_fake --cars 2 --vanish $A2@1
drive vanish MUST=$A1 CROSSINGS=2 SPEED=1200 TIMEOUT=30
check "vanish: the race finishes" 0 "$RC"
line=$(echo "$OUT" | grep "^car ble:$A2 ")
check "vanish: the script saw it go" 1 "$(field disconnects "$line")"
check "vanish: it is not connected" false "$(field connected "$line")"
contains "vanish: the log says so" "$A2 vanished: looking for it again" "$(cat "$TMP/vanish.err")"
stop_fake
contains "vanish: no second connection" "$A2 connected=false target=0 connects=1" \
  "$(cat "$TMP/fake.out")"

# A car that refuses every connection: retried with growing backoff, the other car races
start_fake --cars 2 --refuse $A2
drive refuse MUST=$A1 CROSSINGS=2 SPEED=1200 TIMEOUT=30
check "refuse: the race finishes" 0 "$RC"
err=$(cat "$TMP/refuse.err")
contains "refuse: the failure names the step and BlueZ's reason" \
  "connecting to $A2 failed: le-connection-abort-by-local" "$err"
contains "refuse: first retry" "reconnecting in 0.5 s" "$err"
contains "refuse: backoff doubles" "reconnecting in 1 s" "$err"
check "refuse: the script sees it not connected" false \
  "$(field connected "$(echo "$OUT" | grep "^car ble:$A2 ")")"
stop_fake

# Only the cars asked for
start_fake --cars 3
drive car MUST=$A2 CROSSINGS=1 TIMEOUT=20 -- --car $A2
check "--car: exit status" 0 "$RC"
check "--car: only that car" "car ble:$A2" "$(echo "$OUT" | grep -o '^car ble:[^ ]*')"
stop_fake

# Nothing found
start_fake --cars 0
err=$($PITWALL run "$SRC/tests/ble/laps.lua" --ble --scan-timeout 0.3 2>&1 >/dev/null); rc=$?
check "no car: exit status" 2 "$rc"
contains "no car: says what to check" "no Anki car found on hci0" "$err"

finish
