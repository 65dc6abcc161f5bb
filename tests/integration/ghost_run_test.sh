# Racing a ghost (docs/racing.md "Racing a ghost", "Personal bests"): `pitwall run --ghost
# FILE[:CAR[:LAP]]` puts a ghost of that lap beside the cars; the race library leaves it out of
# the race, starts it at the green light and stops it at the end; it laps in the recorded time
# within a tick (5 ms). Every race kept in the standings keeps each driver's best lap as a trace,
# and `--ghost best[:NAME]` races it. What cannot be a ghost is a sentence, before any car moves
# and before the record is touched.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/ghost_lib.sh"
cd "$TMP" || exit 2
export PITWALL_DB="$TMP/st.db"

$PITWALL run "$SRC/tests/integration/compare_drive.lua" --fast --no-db --record even.jsonl -q ||
  fail "the lap's record"
best=$($PITWALL compare even.jsonl even.jsonl --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["laps"][0]["time"])')
echo "the recorded best lap: $best s"

cp "$SRC/tests/integration/ghost_run.lua" race.lua
GHOST_LAPS=6 $PITWALL run race.lua --fast --cars 2 --ghost even.jsonl --record raced.jsonl --results res.json \
  > out.txt 2> err.txt
check "a race with --ghost: exit status" 0 $?
contains "the lap it drives is said" "ghost drives even.jsonl car 1 (groundshock) lap" "$(cat err.txt)"
contains "the ghost is no entry, stands until the green light and after the race" \
  "entries:	2	ghost moved before green:	false" "$(cat out.txt)"
contains "the ghost stands after the race" "ghost speed after:	0" "$(cat out.txt)"
check "the results have the two cars only" "groundshock skull" \
  "$(python3 -c 'import json; print(" ".join(sorted(e["car"] for e in json.load(open("res.json")))))' 2>&1)"
ghost_laps raced.jsonl "$best" 3 0.005

# Personal bests: each entry's best whole lap, kept as a trace; none of the ghost
python3 - "$PITWALL_DB" > bests.txt <<'PY'
import json, sqlite3, sys
db = sqlite3.connect(sys.argv[1])
for driver, car, lap, trace in db.execute("SELECT driver, car, lap, trace FROM best_laps ORDER BY car"):
    t = json.loads(trace)
    assert abs(t["time"] - lap) < 1e-9 and t["points"][-1][0] == t["time"], (lap, t["time"])
    print(driver, car, "%.3f" % lap, len(t["points"]) > 2)
PY
check "the standings keep both cars' best laps as traces" 2 "$(wc -l < bests.txt)"
contains "groundshock's best lap is kept" "groundshock groundshock" "$(cat bests.txt)"
pb=$(awk '$2 == "skull" { print $3 }' bests.txt)
best_of=$(python3 -c 'import json; print(min(e["bestLap"] for e in json.load(open("res.json")) if e["car"] == "skull"))')
python3 -c "import sys; sys.exit(abs($pb - $best_of) > 0.005)" && echo "ok: skull's kept best is its race's best lap ($pb, $best_of)" ||
  fail "skull's kept best $pb is not its race's best lap $best_of"

# --ghost best:skull races the kept lap again
$PITWALL run race.lua --fast --cars 2 --ghost best:skull --record pb.jsonl > out2.txt 2> err2.txt
check "--ghost best:skull: exit status" 0 $?
contains "the personal best is named" "ghost drives skull's personal best in skull" "$(cat err2.txt)"
ghost_laps pb.jsonl "$pb" 3 0.005

# What an adversary plants is no personal best: a lap driven before the race's green light, a
# trace and layout a script made up, an entry whose number is another car's
PITWALL_DB="$TMP/cheat.db" $PITWALL run "$SRC/tests/integration/ghost_pb_cheat.lua" --fast --cars 1 \
  > cheat.txt 2> cheat.err
check "the planted bests: exit status" 0 $?
kept=$(python3 -c "import sqlite3; print('\n'.join('%s %s %.3f' % r for r in sqlite3.connect('$TMP/cheat.db').execute('SELECT driver, car, lap FROM best_laps ORDER BY car')))")
echo "kept: $kept"
within() {  # within LINES-A LINES-B: the same drivers and cars, each lap within 5 ms
  python3 -c "
import sys
a = sorted(l.split() for l in sys.argv[1].splitlines())
b = sorted(l.split() for l in sys.argv[2].splitlines())
assert a, 'no race best to compare'
assert [x[:2] for x in a] == [x[:2] for x in b], (a, b)
assert all(abs(float(x[2]) - float(y[2])) <= 0.005 for x, y in zip(a, b)), (a, b)" "$1" "$2"
}
within "$(sed -n 's/^race best: //p' cheat.txt)" "$kept" &&
  echo "ok: only the race's laps are kept: not the faster one before the green, not a script's" ||
  fail "the kept bests are not the race's laps: $kept"

# What cannot be a ghost: a sentence, exit status 2, no car moved, an old record untouched
echo '{"old": "record"}' > old.jsonl
cp old.jsonl old.copy
refused() {  # refused NAME EXPECTED ARGS…
  local name=$1 want=$2
  shift 2
  $PITWALL run race.lua --fast --cars 2 --record old.jsonl "$@" > /dev/null 2> bad.err
  check "$name: exit status" 2 $?
  contains "$name: the sentence" "$want" "$(cat bad.err)"
  cmp -s old.jsonl old.copy && echo "ok: $name: the old record is untouched" ||
    fail "$name: the old record was touched"
  if grep -q "connected" bad.err; then fail "$name: a car was connected"; fi
}
refused "a missing record" "--ghost cannot read nope.jsonl: no such file" --ghost nope.jsonl
refused "a lap the record lacks" "has no lap 99" --ghost even.jsonl:1:99
refused "another track" "a ghost drives the track it was on" --ghost even.jsonl --track kidney
refused "a seat on the ghost" "--humans 3 with --ghost: car 3 is the ghost, which no one drives" \
  --ghost even.jsonl --humans 3
refused "no standings" "--ghost best races a personal best the standings keep, and this run keeps none" \
  --ghost best --no-db
refused "no one of that name" "keeps no personal best of nobody on this track" --ghost best:nobody
refused "no best on this track" "keeps no personal best on this track (start" --ghost best --track kidney
python3 -c "
import sqlite3; db = sqlite3.connect('$PITWALL_DB')
db.execute(\"UPDATE best_laps SET trace = '{\\\"lap\\\": 1, \\\"time\\\": 1, \\\"length\\\": 5, \\\"points\\\": [[0,0,null,null],[2,1,null,null]]}'\"); db.commit()"
refused "a damaged best" "keeps skull's personal best in skull" --ghost best:skull
contains "a damaged best: what is wrong" "damaged (a kept lap does not run from the line round to the line)" "$(cat bad.err)"

exit $((FAILURES > 0))
