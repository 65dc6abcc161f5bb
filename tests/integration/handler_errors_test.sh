# A car whose script keeps failing slows to a stop (docs/safety.md, issue 33 finding 9): car 2's
# curve handler fails on every transition; after --handler-errors of them the car gets its stop,
# this script's commands to it are refused (no set-speed but 0 reaches it again), and car 1 races
# on. With --handler-errors 0 the failing car drives on, as before.
source "$(dirname "$0")/lib.sh"

SCRIPT="$SRC/tests/integration/handler_errors.lua"

$PITWALL run "$SCRIPT" --fast --duration 30 --cars 2 --record "$TMP/r.jsonl" \
  >"$TMP/r.out" 2>"$TMP/r.err"
check "exit status" 0 $?
contains "one sentence names the car, the handler and the error" \
  "was stopped: its onTransition handler failed 5 times within 10 s (last: " "$(cat "$TMP/r.err")"
contains "... and what to do" "fix the handler and save the script" "$(cat "$TMP/r.err")"
check "said once" 1 "$(grep -c 'was stopped: its onTransition handler' "$TMP/r.err")"
contains "the script's later commands to it are refused" "it takes no command from this script" \
  "$(cat "$TMP/r.out")"
# From car 2's stop on: what each car was sent, as "car speed" lines of set-speed frames.
after_stop() {
  python3 - "$1" <<'PY'
import json, sys
frames = [json.loads(l) for l in open(sys.argv[1])]
tx = [(f["car"], f["msg"].get("speed_mm_s")) for f in frames
      if f.get("dir") == "tx" and f["msg"]["name"] == "set-speed"]
stop = next(i for i, (car, speed) in enumerate(tx) if car == 2 and speed == 0)
later = tx[stop + 1:]
print("car 2 sent a speed above 0 after its stop:", any(c == 2 and s > 0 for c, s in later))
print("car 1 commanded after car 2's stop:", sum(1 for c, s in later if c == 1 and s > 0) > 10)
PY
}
check "the failing car stays stopped, the other races on" \
  "car 2 sent a speed above 0 after its stop: False
car 1 commanded after car 2's stop: True" "$(after_stop "$TMP/r.jsonl")"
expect_stopped "the end of the run" "$TMP/r.jsonl" 2

$PITWALL run "$SCRIPT" --fast --duration 30 --cars 2 --handler-errors 0 \
  --record "$TMP/z.jsonl" >/dev/null 2>"$TMP/z.err"
check "--handler-errors 0: exit status" 0 $?
check "--handler-errors 0: no stop for the failing car" 0 \
  "$(grep -c 'was stopped: its' "$TMP/z.err")"

finish
