# Captures without times (docs/cli.md "Captures without times"): every frame a real car sent
# (tests/realdata) replays through `pitwall replay` — the summary and a script's handlers — with
# nothing malformed, its times inferred from the car's speeds and wheel distances, or at a stated
# interval; a record with times refuses --interval.
source "$(dirname "$0")/lib.sh"
REAL=$SRC/tests/realdata

# every okoeth run: all its frames in, none malformed
for capture in "$REAL"/okoeth/lane?_speed???.txt; do
  run=$(basename "$capture" .txt)
  out=$($PITWALL replay "$capture" --json 2>"$TMP/$run.err"); rc=$?
  check "$run: exit status" 0 "$rc"
  got=$(echo "$out" | python3 -c 'import json,sys; r=json.loads(sys.stdin.readline()); print(r["framesIn"], r["malformed"])')
  check "$run: every frame in, none malformed" "$(wc -l <"$capture") 0" "$got"
done
contains "the times are inferred, and said so" "a capture without times: times inferred" \
  "$(cat "$TMP/lane3_speed750.err")"

# IBM's 0x266e examples: the one-field speed update is no longer malformed
out=$($PITWALL replay "$REAL/ibm/messages.txt" --json 2>"$TMP/ibm.err")
check "IBM's examples: every frame in, none malformed" "13 0" \
  "$(echo "$out" | python3 -c 'import json,sys; r=json.loads(sys.stdin.readline()); print(r["framesIn"], r["malformed"])')"

# a record whose "t" is the frame's index: timed as a capture, and said so
python3 - "$REAL/okoeth/lane3_speed750.txt" "$TMP/indexed.rec" <<'PY'
import json, sys
with open(sys.argv[1]) as f, open(sys.argv[2], "w") as out:
    for line in f:
        index, car, *hexes = line.split()
        out.write(json.dumps({"t": int(index), "car": 1, "dir": "rx", "hex": " ".join(hexes)}) + "\n")
PY
out=$($PITWALL replay "$TMP/indexed.rec" --json 2>"$TMP/indexed.err")
check "an indexed record: every frame in, none malformed" "$(wc -l <"$REAL/okoeth/lane3_speed750.txt") 0" \
  "$(echo "$out" | python3 -c 'import json,sys; r=json.loads(sys.stdin.readline()); print(r["framesIn"], r["malformed"])')"
contains "an indexed record: said so" '"t" counts its frames (0, 1, 2, …), not seconds: times inferred' \
  "$(cat "$TMP/indexed.err")"

# a stated interval
$PITWALL replay "$REAL/okoeth/lane2_speed750.txt" --interval 0.05 >/dev/null 2>"$TMP/interval.err"
contains "--interval: said" "times at the stated interval, 0.050000 s a frame" "$(cat "$TMP/interval.err")"

# a script's handlers see every transition, in order, a piece's time apart at 750 mm/s
cat >"$TMP/pieces.lua" <<'LUA'
local last
for _, car in ipairs(pitwall.cars()) do
  car.onTransition = function(_, ev)
    print(string.format("transition %.3f %s", ev.time, last and string.format("%.3f", ev.time - last) or "-"))
    last = ev.time
  end
end
LUA
$PITWALL replay "$REAL/okoeth/lane3_speed750.txt" --script "$TMP/pieces.lua" >"$TMP/pieces.out" 2>"$TMP/pieces.err"
check "--script on a capture: exit status" 0 "$?"
check "--script: a transition per 0x29 of the capture" "$(grep -c ' 11 29 ' "$REAL/okoeth/lane3_speed750.txt")" \
  "$(grep -c '^transition' "$TMP/pieces.out")"
median=$(awk '$1 == "transition" && $3 != "-" {print $3}' "$TMP/pieces.out" | sort -n |
  awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}')
python3 -c "import sys; m = float('$median'); sys.exit(0 if 0.5 < m < 0.9 else 1)" &&
  echo "ok: a piece takes ${median} s at 750 mm/s" || fail "a piece takes ${median} s at 750 mm/s"

# --interval is for captures: a record with times refuses it
echo '{"t":0.1,"car":1,"dir":"rx","hex":"01 17"}' >"$TMP/timed.rec"
out=$($PITWALL replay "$TMP/timed.rec" --interval 0.05 2>&1); rc=$?
check "--interval on a record with times: exit status" 2 "$rc"
contains "--interval on a record with times: says why" "has its times" "$out"

finish
