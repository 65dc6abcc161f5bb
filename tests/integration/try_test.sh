# pitwall try FILE (docs/cli.md): a driver file alone in the simulator, virtual time, real sensor
# model — its laps, its best and its speed along the lap, as text or one JSON object whose trace
# follows the car (distance within a lap growing, speed within the car's range); a driver that
# fails is out with the engine's sentence (exit 1), as is one that never finishes; a file that is
# not there, or a layout that does not load, is a usage error (exit 2).
source "$(dirname "$0")/lib.sh"
D="$SRC/tests/integration/drivers"

out=$("$PITWALL" try "$D/good.lua" -q 2>"$TMP/err"); rc=$?
echo "$out"
check "a good driver: exit status" 0 "$rc"
contains "says where it drove" "good.lua alone on oval (real sensors)" "$out"
check "three laps by default" 3 "$(echo "$out" | grep -cE '^  lap [0-9]+  [0-9.]+ s')"
check "one best lap" 1 "$(echo "$out" | grep -c '  best$')"
contains "its speed along the best lap" "(mm/s): 0.0 m " "$out"

"$PITWALL" try "$D/good.lua" --laps 2 --json -q >"$TMP/try.json" 2>"$TMP/err"; rc=$?
check "--json: exit status" 0 "$rc"
python3 - "$TMP/try.json" <<'PY' >"$TMP/checks"
import json, sys
d = json.load(open(sys.argv[1]))
print("laps", len(d["laps"]), "status", d["status"], "best", d["best"] == min(d["laps"]))
lap1 = [s for s in d["trace"] if s["lap"] == 1]
grows = all(b["distance"] >= a["distance"] for a, b in zip(lap1, lap1[1:]))
within = all(0 <= s["speed"] <= 1500 for s in d["trace"])
print("trace", len(lap1) > 40, "grows", grows, "within", within,
      "times", all(b["time"] > a["time"] for a, b in zip(d["trace"], d["trace"][1:])))
PY
check "--json: the laps, the status, the best" "laps 2 status finished best True" "$(head -1 "$TMP/checks")"
check "--json: the trace follows the car through lap 1" "trace True grows True within True times True" "$(tail -1 "$TMP/checks")"

printf 'return {\n  update = function(self, car)\n    car:setSpeed(\n  end,\n}\n' >"$TMP/broken.lua"
out=$("$PITWALL" try "$TMP/broken.lua" -q 2>"$TMP/err"); rc=$?
check "a broken driver: exit status" 1 "$rc"
contains "it is out with the engine's sentence" "out after 0 laps: its file does not load: " "$out"
contains "... and line" "broken.lua:4: unexpected symbol near 'end'" "$out"
printf 'while true do end\n' >"$TMP/loop.lua"
out=$("$PITWALL" try "$TMP/loop.lua" -q 2>"$TMP/err"); rc=$?
check "a looping driver: exit status" 1 "$rc"
contains "it is out on its budget" "still running after 50 ms" "$out"

printf 'return { update = function(self, car) car:setSpeed(0) end }\n' >"$TMP/stand.lua"
out=$("$PITWALL" try "$TMP/stand.lua" --laps 1 -q 2>"$TMP/err"); rc=$?
check "a driver that never finishes (no failure): exit status" 1 "$rc"
contains "it says so" "out after 0 laps: it did not finish its laps (DNF)" "$out"

out=$("$PITWALL" try "$TMP/missing.lua" 2>&1); rc=$?
check "a file that is not there: exit status" 2 "$rc"
contains "names it" "$TMP/missing.lua: no such file" "$out"

out=$("$PITWALL" try "$D/good.lua" --track nosuch 2>&1); rc=$?
check "a layout that does not load: exit status" 2 "$rc"
contains "says what to give" "layout 'nosuch' is neither a named layout" "$out"
finish
