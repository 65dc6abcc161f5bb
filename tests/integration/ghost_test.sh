# The simulator's ghost (docs/simulator.md "Ghosts"): sim.addGhost drives a record's lap again,
# lap after lap, in the recorded time within a tick (5 ms), in the lane it was driven in,
# touching no car; it is marked as a ghost in Lua and in the view's state; what cannot be a
# ghost is a sentence.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/ghost_lib.sh"
cd "$TMP" || exit 2

$PITWALL run "$SRC/tests/integration/compare_drive.lua" --fast --record even.jsonl -q || fail "the lap's record"
best=$($PITWALL compare even.jsonl even.jsonl --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["laps"][0]["time"])')
echo "the recorded best lap: $best s"

cp "$SRC/tests/integration/ghost_drive.lua" ghost.lua
$PITWALL run ghost.lua --fast --record ghost.jsonl > out.txt 2> err.txt
check "the run with a ghost: exit status" 0 $?
contains "the ghost is one in Lua, the car is not" "ghost:	ghost	true	false" "$(cat out.txt)"
contains "the lap it drives is said" "ghost drives even.jsonl car 1 (groundshock) lap" "$(cat err.txt)"
contains "no lane change, no collision" "ghost offset:	-68.0	collisions:	0" "$(cat out.txt)"
# its laps, counted from its own frames by the replay: the recorded lap's time within a tick
ghost_laps ghost.jsonl "$best" 4 0.005

# what cannot be a ghost
try() {  # try NAME LUA EXPECTED
  printf 'local sim = require "pitwall.sim"\n%s\npitwall.stop()\n' "$2" > bad.lua
  $PITWALL run bad.lua --fast > /dev/null 2> bad.err
  check "$1: exit status" 1 $?
  contains "$1: the sentence" "$3" "$(cat bad.err)"
}
try "no record" 'sim.addGhost{}' "sim.addGhost needs record=, the --record file that holds the lap"
try "a missing file" 'sim.addGhost{record="nope.jsonl"}' "sim.addGhost: cannot read nope.jsonl: no such file"
try "a lap the record lacks" 'sim.addGhost{record="even.jsonl", lap=99}' "has no lap 99: its whole laps are"
try "a car that drove no lap" 'sim.addGhost{record="even.jsonl", car=2}' "car 2 (skull) drove no whole lap"
try "a lap that is no number" 'sim.addGhost{record="even.jsonl", lap="fast"}' "sim.addGhost: lap= must be a lap's number or \"best\", not 'fast'"
$PITWALL run "$SRC/tests/integration/compare_drive.lua" --fast --track kidney --record kidney.jsonl -q
try "another track" 'sim.addGhost{record="kidney.jsonl"}' "a ghost drives the track it was on"
# a record whose times were squeezed a million-fold: its laps are faster than any car
python3 - <<'PY'
import json
with open("even.jsonl") as src, open("squeezed.jsonl", "w") as out:
    for line in src:
        d = json.loads(line)
        d["t"] = d["t"] * 1e-6
        out.write(json.dumps(d) + "\n")
PY
try "a lap faster than any car" 'sim.addGhost{record="squeezed.jsonl"}' "faster than any car (5000 mm/s): the record's times are wrong"
head -c 600000 /dev/zero | tr '\0' ' ' > huge.jsonl
try "a record too large" 'sim.addGhost{record="huge.jsonl"}' "huge.jsonl is 586 KB, more than the 512 KB a ghost's record may be"

exit $((FAILURES > 0))
