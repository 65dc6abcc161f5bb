# A race over Bluetooth LE as a user runs it: `pitwall run SCRIPT --ble` against the fake BlueZ,
# whose cars are simulated behind D-Bus. Four cars on two adapters lap; a clean end stops and
# disconnects every car; Ctrl-C does the same.
source "$(dirname "$0")/ble_lib.sh"
source "$(dirname "$0")/ghost_lib.sh"
start_bus

# --ble is for real cars: simulator options are refused with it
err=$($PITWALL run "$SRC/tests/ble/laps.lua" --ble --fast 2>&1 >/dev/null); rc=$?
check "--ble with --fast: exit status" 2 "$rc"
contains "--ble with --fast: says why" "excludes" "$err"

start_fake --adapters 2 --cars 4
out=$(CROSSINGS=2 SPEED=1200 TIMEOUT=30 $PITWALL run "$SRC/tests/ble/laps.lua" --ble \
  --scan-timeout 1 2>"$TMP/run.err"); rc=$?
check "race: exit status" 0 "$rc"
check "race: a summary line per car" 4 "$(echo "$out" | grep -c '^car ble:')"
for n in 1 2 3 4; do
  line=$(echo "$out" | grep "^car ble:E0:00:00:00:00:0$n ")
  contains "race: car $n lapped" "connected=true" "$line"
  laps=$(echo "$line" | sed -n 's/.*laps=\([0-9]*\).*/\1/p')
  [ "${laps:-0}" -ge 2 ] && echo "ok: race: car $n crossed the line twice" ||
    fail "race: car $n crossed the line ${laps:-0} times: $line"
done
err=$(cat "$TMP/run.err")
contains "race: cars spread over hci0" "at E0:00:00:00:00:01 on hci0" "$err"
contains "race: and hci1" "at E0:00:00:00:00:02 on hci1" "$err"
stop_fake
summary=$(cat "$TMP/fake.out")
for n in 1 2 3 4; do
  contains "race: car $n left stopped and disconnected" \
    "E0:00:00:00:00:0$n connected=false target=0" "$summary"
done

# A ghost beside real cars (docs/racing.md "Racing a ghost"): --ble --track gives it the layout,
# it drives a simulated world of its own beside the cars, from the green light, and laps in the
# recorded lap's time (within 0.1 s: in real time a frame is stamped when the loop reads it, late on
# a loaded machine; the virtual-time tests hold it to a tick); without --track it is refused before any car is connected
$PITWALL run "$SRC/tests/integration/compare_drive.lua" --fast --no-db --record "$TMP/even.jsonl" -q
best=$($PITWALL compare "$TMP/even.jsonl" "$TMP/even.jsonl" --json |
  python3 -c 'import json,sys; print(json.load(sys.stdin)["laps"][0]["time"])')
err=$($PITWALL run "$SRC/tests/integration/ghost_run.lua" --ble --scan-timeout 1 --no-db \
  --ghost "$TMP/even.jsonl" 2>&1 >/dev/null); rc=$?
check "ghost without --track: exit status" 2 "$rc"
contains "ghost without --track: says why" "--ghost with --ble needs --track LAYOUT" "$err"
start_fake --adapters 1 --cars 2
out=$(GHOST_LAPS=4 $PITWALL run "$SRC/tests/integration/ghost_run.lua" --ble --scan-timeout 1 \
  --track oval --no-db --ghost "$TMP/even.jsonl" --record "$TMP/ghost.jsonl" 2>"$TMP/ghost.err"); rc=$?
check "ghost beside real cars: exit status" 0 "$rc"
contains "ghost beside real cars: the ghost is no entry and waits for the green light" \
  "entries:	2	ghost moved before green:	false" "$out"
contains "ghost beside real cars: stopped at the end" "ghost speed after:	0" "$out"
stop_fake
ghost_laps "$TMP/ghost.jsonl" "$best" 2 0.1 --track oval

# Ctrl-C: the cars are stopped, then disconnected; exit status 130
start_fake --adapters 1 --cars 2
mkfifo "$TMP/run.fifo"
CROSSINGS=1000 TIMEOUT=600 $PITWALL --log-level debug run "$SRC/tests/ble/laps.lua" --ble \
  --scan-timeout 0.5 2>"$TMP/run.fifo" >/dev/null &
RUN_PID=$!
exec 4<"$TMP/run.fifo"
# wait until both cars are up, as the run's own log says
up=0
while read -r -t 20 -u 4 line; do
  case "$line" in *": connected"*) up=$((up + 1)) ;; esac
  [ $up -eq 2 ] && break
done
check "ctrl-c: both cars connected first" 2 "$up"
kill -INT $RUN_PID
cat <&4 >"$TMP/ctrlc.err" 2>/dev/null &  # the rest of the log, until pitwall exits
wait $RUN_PID; rc=$?
check "ctrl-c: exit status" 130 "$rc"
stop_fake
summary=$(cat "$TMP/fake.out")
contains "ctrl-c: car 1 stopped and disconnected" "E0:00:00:00:00:01 connected=false target=0" "$summary"
contains "ctrl-c: car 2 stopped and disconnected" "E0:00:00:00:00:02 connected=false target=0" "$summary"

finish
