# From simulation to track (docs/league.md "The final"): a league of driver files is raced in the
# simulator and kept in a standings database; `pitwall run --ble --league-final DB` then races its
# top drivers on "real" cars — the fake BlueZ's, over D-Bus — with the same files, the grid in the
# order of the league's standings (its winner on car 1), to a result kept in the same database as
# the final. Every car's last frame is its stop. A finalist whose file is gone, a database without
# a league and --driver beside --league-final are refused before any car is connected.
source "$(dirname "$0")/ble_lib.sh"
start_bus
D="$SRC/tests/integration/drivers"
good_class "$TMP/class"
export PITWALL_DB="$TMP/default.db"
DB="$TMP/class.db"

$PITWALL league "$TMP/class" --laps 2 --qualifying-laps 1 --cars 3 --db "$DB" \
  --results "$TMP/league.json" >/dev/null 2>"$TMP/league.err"
check "the league: exit status" 0 "$?"
top=$(python3 -c "
import json; print(' '.join(s['driver'] for s in json.load(open('$TMP/league.json'))['standings'][:3]))")

# The final: the league's top three (its heats had three cars) on three cars
start_fake --adapters 1 --cars 3
$PITWALL run --ble --league-final "$DB" --scan-timeout 1 --record "$TMP/final.jsonl" \
  --results "$TMP/final.json" >"$TMP/final.out" 2>"$TMP/final.err"
rc=$?
stop_fake
check "the final: exit status" 0 "$rc"
err=$(cat "$TMP/final.err")
contains "the final: names its finalists, in the league's order" \
  "final: Final: class, 2 laps: $(echo "$top" | sed 's/ /, /g')" "$err"
contains "the final: a winner" "Winner:" "$(cat "$TMP/final.out")"
contains "the final: kept in the league's database" "kept in the standings: $DB" "$err"
# what the database kept: a final of the three, each on the car of its place in the league
kept=$(python3 - "$DB" <<'PY'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
rows = db.execute("SELECT e.kind, e.title, ra.kind, r.number, r.driver, r.finished, r.laps, "
                  "r.file FROM results r JOIN races ra ON ra.id = r.race JOIN events e ON "
                  "e.id = ra.event WHERE e.kind = 'final' ORDER BY r.number").fetchall()
print(" ".join(r[4] for r in rows))
print({(r[0], r[1], r[2]) for r in rows})
print(all(r[5] == 1 and r[6] == 2 for r in rows), all(r[7].endswith(r[4] + ".lua") for r in rows))
PY
)
check "the final: cars 1-3 driven by the league's first three, each two laps with its file" "$top
{('final', 'Final: class', 'final')}
True True" "$kept"
# the results file too: the drivers' cars, finished
check "the final: three results" 3 "$(python3 -c "import json; print(len(json.load(open('$TMP/final.json'))))")"
for n in 1 2 3; do
  contains "the final: car $n left stopped" "E0:00:00:00:00:0$n connected=false target=0" \
    "$(cat "$TMP/fake.out")"
done
expect_stopped "the final" "$TMP/final.jsonl" 3
out=$($PITWALL standings --db "$DB" --events)
contains "standings --events: the final beside its league" "final   " "$out"
check "nothing went to the default database" "" "$(ls "$PITWALL_DB" 2>/dev/null)"

# --final-cars 2: the first two race; a third car found stays where it is, undriven
start_fake --adapters 1 --cars 3
$PITWALL run --ble --league-final "$DB" --final-cars 2 --scan-timeout 1 \
  --results "$TMP/two.json" >/dev/null 2>"$TMP/two.err"
rc=$?
stop_fake
check "--final-cars 2: exit status" 0 "$rc"
check "--final-cars 2: two results" 2 "$(python3 -c "import json; print(len(json.load(open('$TMP/two.json'))))")"
contains "--final-cars 2: the first two" "final: Final: class, 2 laps: $(echo "$top" | cut -d' ' -f1-2 | sed 's/ /, /')" "$(cat "$TMP/two.err")"
check "--final-cars 2: the third car never moved" "" \
  "$(grep "E0:00:00:00:00:03" "$TMP/fake.out" | grep -v "target=0")"

# Refused before any car is connected: the fake sees no connection
start_fake --adapters 1 --cars 3
mv "$TMP/class/$(echo "$top" | cut -d' ' -f2).lua" "$TMP/gone.lua"
err=$($PITWALL run --ble --league-final "$DB" --scan-timeout 1 2>&1); rc=$?
check "a finalist's file gone: refused" 2 "$rc"
contains "a finalist's file gone: says whose, and what to do" "(place 2 of the league) drove" "$err"
contains "a finalist's file gone: …put it back" "put the file back where it was" "$err"
mv "$TMP/gone.lua" "$TMP/class/$(echo "$top" | cut -d' ' -f2).lua"
err=$($PITWALL run --ble --league-final "$PITWALL_DB" --scan-timeout 1 2>&1); rc=$?
check "no such database: refused" 2 "$rc"
contains "no such database: says so" "no standings at $PITWALL_DB yet" "$err"
err=$($PITWALL run --ble --league-final "$DB:99" --scan-timeout 1 2>&1); rc=$?
check "no such league: refused" 2 "$rc"
contains "no such league: says where to look" "has no league 99 (pitwall standings --events" "$err"
err=$($PITWALL run --ble --league-final "$DB" --driver 1="$TMP/class/alice.lua" 2>&1); rc=$?
check "--driver with --league-final: refused" 2 "$rc"
contains "--driver with --league-final: says why" "no --driver with it" "$err"
stop_fake
check "refused: no car was connected" "" "$(grep -E "connects=[1-9]" "$TMP/fake.out")"

[ "$FAILURES" -eq 0 ] || { echo "$FAILURES failure(s)"; exit 1; }
echo "all league final checks passed"
