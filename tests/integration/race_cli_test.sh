# The race director from the command line: the grand prix example on the simulator writes its
# results with --results FILE, as JSON and as CSV, and both parse back with one row per car; the
# same script runs unchanged over --ble (the fake BlueZ, real time: about 30 s).
source "$(dirname "$0")/ble_lib.sh"

for ext in json csv; do
  out=$(LAPS=3 $PITWALL run "$SRC/examples/grand_prix.lua" --fast --cars 4 --results "$TMP/gp.$ext" 2>"$TMP/err"); rc=$?
  check "grand prix ($ext) exit status" 0 "$rc"
  contains "grand prix ($ext) prints the results table" "POS  CAR" "$out"
  contains "grand prix ($ext) names the winner" "Winner: " "$out"
  if grep -q "error " "$TMP/err"; then fail "grand prix ($ext) reported an error: $(cat "$TMP/err")"; fi
  check "grand prix ($ext) results file written" yes "$([ -s "$TMP/gp.$ext" ] && echo yes)"
done

parsed=$(/usr/bin/python3 - "$TMP/gp.json" "$TMP/gp.csv" <<'PY'
import csv, json, sys
rows = json.load(open(sys.argv[1]))
assert isinstance(rows, list) and len(rows) == 4, rows
assert [r["position"] for r in rows] == [1, 2, 3, 4], rows
for r in rows:
    for k in ("car", "laps", "totalTime", "bestLap", "lastLap"):
        assert k in r, (k, r)
    assert r["finished"] is True and r["falseStart"] is False, r
    assert r["status"] == "finished" and r["driver"] in ("cruiser", "lanekeeper", "follower", "overtaker"), r
    assert r["bestLap"] <= r["lastLap"] + 1e-9, r
assert rows[0]["laps"] == 3, rows[0]
crows = list(csv.DictReader(open(sys.argv[2])))
assert len(crows) == 4, crows
assert [int(r["position"]) for r in crows] == [1, 2, 3, 4], crows
# the same race (same seed) gives the same results in both formats
for j, c in zip(rows, crows):
    assert j["car"] == c["car"] and j["laps"] == int(c["laps"]), (j, c)
    assert abs(j["totalTime"] - float(c["totalTime"])) < 1e-6, (j, c)
print("parsed", len(rows), len(crows))
PY
)
check "JSON and CSV results parse back" "parsed 4 4" "$parsed"

# On a track of custom pieces (examples/tracks/hairpin.layout, docs/tracks.md): the AI drivers
# race it to a winner, every car finishing its laps.
out=$(LAPS=3 $PITWALL run "$SRC/examples/grand_prix.lua" --fast --cars 4 \
  --track "$SRC/examples/tracks/hairpin.layout" --results "$TMP/hairpin.csv" 2>"$TMP/err"); rc=$?
check "grand prix on a custom track: exit status" 0 "$rc"
contains "grand prix on a custom track: the winner" "Winner: " "$out"
if grep -q "error " "$TMP/err"; then fail "custom track reported an error: $(cat "$TMP/err")"; fi
check "grand prix on a custom track: every car finished" 4 "$(grep -c ',true,false,[a-z]*,[^,]*,finished,$' "$TMP/hairpin.csv")"

out=$(LAPS=2 $PITWALL run "$SRC/examples/time_trial.lua" --fast --cars 3 --results "$TMP/tt.csv" 2>/dev/null); rc=$?
check "time trial exit status" 0 "$rc"
contains "time trial names the fastest lap" "Fastest lap: " "$out"
check "time trial rows" 4 "$(wc -l < "$TMP/tt.csv" | tr -d ' ')"

# A run cut short mid-race (--duration): the race says where it stood, once — the final table
# titled "stopped", the results file with every car unfinished — and the run exits 0 as asked.
# (the scan lap from the inner lane takes about 32 s under the real sensor model, the race
# goes green at about 40 s and lasts about 20)
out=$(LAPS=5 $PITWALL run "$SRC/examples/grand_prix.lua" --fast --cars 4 --duration 50 \
  --results "$TMP/cut.csv" 2>"$TMP/cut.err"); rc=$?
check "cut short: exit status" 0 "$rc"
check "cut short: the final table once" 1 "$(echo "$out" | grep -c 'Grand prix, 5 laps   stopped')"
check "cut short: no winner" "" "$(echo "$out" | grep '^Winner')"
contains "cut short: says so" "the run ended before the Grand prix, 5 laps did" "$(cat "$TMP/cut.err")"
check "cut short: a row per car" 5 "$(wc -l <"$TMP/cut.csv" | tr -d ' ')"
check "cut short: nobody finished" 4 "$(grep -c ',false,false,[a-z]*,[^,]*,running,$' "$TMP/cut.csv")"

# --ble: scan lap, grid, lights, one lap; every car left stopped and disconnected
start_bus
start_fake --adapters 1 --cars 4
out=$(LAPS=1 $PITWALL run "$SRC/examples/grand_prix.lua" --ble --scan-timeout 1 \
  --results "$TMP/ble.csv" 2>"$TMP/ble.err"); rc=$?
check "grand prix over --ble: exit status" 0 "$rc"
contains "grand prix over --ble: the winner" "Winner: " "$out"
if grep -q "error " "$TMP/ble.err"; then fail "grand prix over --ble reported an error: $(cat "$TMP/ble.err")"; fi
check "grand prix over --ble: a row per car" 5 "$(wc -l < "$TMP/ble.csv" | tr -d ' ')"
check "grand prix over --ble: every car finished its lap" 4 "$(grep -c ',1,[0-9.]*,[0-9.]*,[0-9.]*,true,false,[a-z]*,[^,]*,finished,$' "$TMP/ble.csv")"
stop_fake
check "grand prix over --ble: every car stopped" 4 "$(grep -c 'connected=false target=0 ' "$TMP/fake.out")"

# Real cars on printed pieces: the fake BlueZ's cars drive the custom layout, and --track tells
# the run its custom pieces' shapes, so the scan lap maps them and the race is timed on them.
start_fake --adapters 1 --cars 2 --track "$SRC/examples/tracks/hairpin.layout"
out=$(LAPS=1 $PITWALL run "$SRC/examples/grand_prix.lua" --ble --scan-timeout 1 \
  --track "$SRC/examples/tracks/hairpin.layout" --results "$TMP/ble-hairpin.csv" \
  2>"$TMP/ble-hairpin.err"); rc=$?
check "custom track over --ble: exit status" 0 "$rc"
contains "custom track over --ble: the winner" "Winner: " "$out"
if grep -q "error " "$TMP/ble-hairpin.err"; then fail "custom track over --ble reported an error: $(cat "$TMP/ble-hairpin.err")"; fi
check "custom track over --ble: every car finished its lap" 2 "$(grep -c ',1,[0-9.]*,[0-9.]*,[0-9.]*,true,false,[a-z]*,[^,]*,finished,$' "$TMP/ble-hairpin.csv")"
# People: two seats the script holds (as phones would) race two cruisers; then input loss.
human_race() {  # $1: what runs the cars; the rest: options
  local what=$1; shift
  out=$(LAPS=1 $PITWALL run "$SRC/tests/integration/human_race.lua" --humans 2 "$@" 2>"$TMP/human.err"); rc=$?
  check "humans $what: exit status" 0 "$rc"
  if grep -q "error " "$TMP/human.err"; then fail "humans $what reported an error: $(cat "$TMP/human.err")"; fi
  check "humans $what: both humans finished, no false start" 2 \
    "$(echo "$out" | grep -c ' human laps=1 finished=true falseStart=false')"
  check "humans $what: both AI drivers finished" 2 \
    "$(echo "$out" | grep -c ' cruiser laps=[01] finished=true falseStart=false')"
  contains "humans $what: a silent seat's car stopped" "input loss: moving=true stopped=true" "$out"
}
human_race "on the simulator" --fast --cars 4
echo 'local p = pitwall.piece(61) print(p and string.format("%s r=%g deg=%g", p.type, p.radius, p.angle)) pitwall.stop()' >"$TMP/piece.lua"
out=$($PITWALL run "$TMP/piece.lua" --ble --scan-timeout 1 --track "$SRC/examples/tracks/hairpin.layout" 2>/dev/null)
check "--ble --track: pitwall.piece knows a custom piece" "curve r=400 deg=45" "$out"
out=$($PITWALL run "$TMP/piece.lua" --ble --scan-timeout 1 2>/dev/null)
check "--ble without --track: a custom id is unknown" "nil" "$out"
# …and the layout is the race's map without a scan lap (track.fromLayout): nothing without --track
cat >"$TMP/layout.lua" <<'LUA'
local track = require "pitwall.track"
local l, m = pitwall.layout(), track.fromLayout()
print(l and string.format("%d pieces, map %s %d pieces", #l.pieces, m.source, #m.pieces) or "none")
pitwall.stop()
LUA
out=$($PITWALL run "$TMP/layout.lua" --ble --scan-timeout 1 --track "$SRC/examples/tracks/hairpin.layout" 2>/dev/null)
n=$($PITWALL track show "$SRC/examples/tracks/hairpin.layout" 2>/dev/null | grep -cE '^ *[0-9]+ +id ')
check "--ble --track: pitwall.layout() and track.fromLayout() are the layout" "$n pieces, map layout $n pieces" "$out"
out=$($PITWALL run "$TMP/layout.lua" --ble --scan-timeout 1 2>/dev/null)
check "--ble without --track: no layout" "none" "$out"
stop_fake
start_fake --adapters 1 --cars 4
human_race "over --ble" --ble --scan-timeout 1
stop_fake
out=$($PITWALL run "$SRC/examples/grand_prix.lua" --ble --track "$TMP/none.layout" 2>&1); rc=$?
check "--ble with a missing --track file: exit status" 2 "$rc"
contains "--ble with a missing --track file: says so" "none.layout" "$out"
finish
