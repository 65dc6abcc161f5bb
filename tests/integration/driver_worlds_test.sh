# Driver worlds (docs/drivers.md): each --driver file races in a Lua world of its own, and an
# adversarial one — it commands another car, loops, grows without bound, fails in every method,
# calls os.exit, requires another driver's file, reads a file, or is saved broken mid-race — is
# out: its car stopped, DNF with the reason in the results. The others' results equal those of a
# run where that car stops at the same moment by itself (a well-behaved driver world that stops
# it then), and every car's last frame is its stop. In real time, a driver that uses most of its
# budget in every update is out for taking more than its share of the loop.
source "$(dirname "$0")/lib.sh"
D="$SRC/tests/integration/drivers"

cat > "$TMP/race.lua" <<'LUA'
local race = require "pitwall.race"
race.laps { laps = 3 }
pitwall.stop()
LUA

# A save mid-race: at car 1's first lap, car 2's driver file (a copy of good.lua) is replaced by
# $REPLACEMENT and its world reloaded, as --watch does on a save.
cat > "$TMP/save_race.lua" <<'LUA'
local race = require "pitwall.race"
local saved = false
race.laps { laps = 3, onLap = function(car, lap, session)
  if saved or car.number ~= 1 then return end
  saved = true
  local entry = session:entry(pitwall.cars()[2])
  local text = io.open(os.getenv("REPLACEMENT")):read("a")
  local f = io.open(entry.driver.world.file, "w")
  f:write(text)
  f:close()
  entry.driver.world:reload()
end }
pitwall.stop()
LUA

# the car that stops by itself at engine time T (its first call from then on; at load for 0)
stopper() {
  cat > "$2" <<LUA
local T = $1
local function maybe(self, car)
  if not self.stopped and pitwall.now() >= T - 1e-9 then self.stopped = true car:stop() end
end
if T == 0 then for _, car in ipairs(pitwall.cars()) do pcall(car.stop, car) end end
return { stopped = T == 0, start = maybe, update = maybe, waiting = maybe }
LUA
}

# The results of the cars but car 2, as comparable lines.
others() {
  python3 - "$1" <<'PY'
import json, sys
for r in json.load(open(sys.argv[1])):
    if r["number"] != 2:
        print({k: r[k] for k in ("position", "car", "laps", "totalTime", "bestLap", "lastLap",
                                 "finished", "status")})
PY
}

# car 2's status and reason
second() {
  python3 - "$1" <<'PY'
import json, sys
for r in json.load(open(sys.argv[1])):
    if r["number"] == 2:
        print(r["status"], "|", r.get("reason"))
PY
}

# adversary NAME FILE EXPECTED [SCRIPT REPLACEMENT REFERENCE]
adversary() {
  local name=$1 file=$2 expected=$3 script=${4:-$TMP/race.lua}
  local driver=$file
  if [ -n "${5:-}" ]; then
    driver="$TMP/$name.lua"
    cp "$D/good.lua" "$driver"
  fi
  REPLACEMENT=${5:-} $PITWALL run "$script" --fast --seed 7 --driver-memory 16 \
    --driver 2="$driver" --results "$TMP/$name.json" --record "$TMP/$name.jsonl" \
    >"$TMP/$name.out" 2>"$TMP/$name.err"
  check "$name: exit status" 0 "$?"
  local row
  row=$(second "$TMP/$name.json")
  contains "$name: car 2 is DNF" "DNF | " "$row"
  contains "$name: with the reason" "$expected" "$row"
  contains "$name: the log says so" "is out, its car stopped: " "$(cat "$TMP/$name.err")"
  expect_stopped "$name" "$TMP/$name.jsonl" 4
  # the reference: car 2 stops by itself at the moment the adversary was put out
  local at ref
  at=$(sed -n 's/^\[ *\([0-9.]*\)\] error driver: .*/\1/p' "$TMP/$name.err" | head -1)
  if [ -n "${5:-}" ]; then
    ref="$TMP/$name-ref.lua"
    cp "$D/good.lua" "$ref"
    REPLACEMENT=$6 $PITWALL run "$script" --fast --seed 7 --driver 2="$ref" \
      --results "$TMP/$name-ref.json" >/dev/null 2>"$TMP/$name-ref.err"
  else
    stopper "${at:-0}" "$TMP/$name-ref.lua"
    $PITWALL run "$script" --fast --seed 7 --driver 2="$TMP/$name-ref.lua" \
      --results "$TMP/$name-ref.json" >/dev/null 2>"$TMP/$name-ref.err"
  fi
  local mine theirs
  mine=$(others "$TMP/$name.json")
  theirs=$(others "$TMP/$name-ref.json")
  [ -n "$mine" ] && [ "$(echo "$mine" | grep -c "'finished': True")" = 3 ] &&
    echo "ok: $name: the three others finished" || fail "$name: the others: [$mine]"
  check "$name: the others' results equal a car stopping by itself at ${at:-?} s" "$theirs" "$mine"
}

adversary other_car "$D/other_car.lua" "car 1 (groundshock) is not this driver's car: a driver commands only its own (car 2 (skull))"
adversary loop "$D/loop.lua" "loop.lua:2: still running after 50 ms: interrupted"
adversary grow "$D/grow.lua" "driver memory limit of 16 MB reached"
adversary errors "$D/errors.lua" "errors.lua:2: this driver is broken"
adversary exit "$D/exit.lua" "it called os.exit(3): a driver cannot end the run"
adversary stop "$D/stop.lua" "it called pitwall.stop: a driver cannot end the race"
adversary require_other "$D/require_other.lua" "module 'good' not found"
adversary read_file "$D/read_file.lua" "io.open is not available to scripts: a driver reads and writes no file"
adversary broken_save - "its file does not load:" "$TMP/save_race.lua" "$D/broken_save.lua" \
  "$D/stop_at_load.lua"

# What a driver world reads of the race: ctx.race as the director sees it, sent again each time
# it changes (a view that is the same is not copied again: drivers.lua), and the cars ahead,
# which the world follows from its driver's first ctx:ahead() on.
$PITWALL run "$TMP/race.lua" --fast --seed 7 --driver 2="$D/reader.lua" >"$TMP/reader.out" \
  2>"$TMP/reader.err"
check "a driver reading the race: exit status" 0 "$?"
views=$(python3 - "$TMP/reader.out" <<'PY'
import re, sys
laps = {}  # car → the laps the world saw it at, in order
for line in open(sys.argv[1]):
    m = re.match(r"race view: (\w+) (.*)", line)
    if not m:
        continue
    if m.group(1) != "racing":
        print("phase", m.group(1))
    for item in m.group(2).split():
        car, n = map(int, item.split(":"))
        seen = laps.setdefault(car, [])
        if not seen or seen[-1] != n:
            seen.append(n)
for car in sorted(laps):
    print(car, laps[car])
PY
)
# every car seen at each lap in turn, car 2 (the reader's) up to its last update before the flag
check "the world saw every lap of every car, in order" "1 [0, 1, 2, 3]
2 [0, 1, 2]
3 [0, 1, 2, 3]
4 [0, 1, 2, 3]" "$views"
ahead=$(sed -n 's/^ahead: car \([0-9]*\), .*/\1/p' "$TMP/reader.out")
case "$ahead" in
  1 | 3 | 4) echo "ok: the world's ctx:ahead() found car $ahead" ;;
  *) fail "the world's ctx:ahead() found no other car: [$ahead] $(cat "$TMP/reader.out")" ;;
esac

# A good save brings a driver that was out back: at car 1's second lap (after the broken save at
# its first) the file is good again, and car 2 races to the flag
cat > "$TMP/repair_race.lua" <<'LUA'
local race = require "pitwall.race"
local function save(session, from)
  local entry = session:entry(pitwall.cars()[2])
  local f = io.open(entry.driver.world.file, "w")
  f:write(io.open(from):read("a"))
  f:close()
  entry.driver.world:reload()
end
race.laps { laps = 3, onLap = function(car, lap, session)
  if car.number ~= 1 then return end
  if lap.number == 1 then save(session, os.getenv("BROKEN")) end
  if lap.number == 2 then save(session, os.getenv("GOOD")) end
end }
pitwall.stop()
LUA
cp "$D/good.lua" "$TMP/repaired.lua"
BROKEN="$D/broken_save.lua" GOOD="$D/good.lua" $PITWALL run "$TMP/repair_race.lua" --fast \
  --driver 2="$TMP/repaired.lua" --results "$TMP/repaired.json" --record "$TMP/repaired.jsonl" \
  >/dev/null 2>"$TMP/repaired.err"
check "a repaired driver: exit status" 0 "$?"
err=$(cat "$TMP/repaired.err")
contains "the broken save put it out" "car 2 (skull) is out (DNF)" "$err"
contains "the good save brought it back" "car 2 (skull) is back (driver $TMP/repaired.lua, version 3)" "$err"
contains "it raced to the flag" "finished | None" "$(second "$TMP/repaired.json")"
expect_stopped "a repaired driver" "$TMP/repaired.jsonl" 4

# --watch, in real time: a save of a driver file reloads its world — a broken save puts it out,
# a good one brings it back (an editor's atomic save: write a copy, rename it over the file)
cp "$D/good.lua" "$TMP/watched.lua"
cat > "$TMP/watch_race.lua" <<'LUA'
local race = require "pitwall.race"
race.laps { laps = 2, onLap = function(car, lap)
  if car.number == 1 then pitwall.log("info", "leader's lap " .. lap.number) end
end }
pitwall.stop()
LUA
$PITWALL run "$TMP/watch_race.lua" --watch --driver 2="$TMP/watched.lua" \
  --results "$TMP/watched.json" --record "$TMP/watched.jsonl" >/dev/null 2>"$TMP/watch.err" &
pid=$!
saved() { cp "$1" "$TMP/watched.lua.swp" && mv "$TMP/watched.lua.swp" "$TMP/watched.lua"; }
if wait_for "$TMP/watch.err" "leader's lap 1" 40; then
  saved "$D/broken_save.lua"
  wait_for "$TMP/watch.err" "car 2 \(skull\) is out \(DNF\)" 20 ||
    fail "--watch: a broken save did not put the driver out: $(tail -3 "$TMP/watch.err")"
  saved "$D/good.lua"
  wait_for "$TMP/watch.err" "car 2 \(skull\) is back" 20 ||
    fail "--watch: a good save did not bring it back: $(tail -3 "$TMP/watch.err")"
else
  fail "--watch: the race never reached its first lap: $(tail -3 "$TMP/watch.err")"
fi
wait_bounded $pid
check "--watch: exit status" 0 "$?"
contains "--watch: the save's reload is said" "driver watched.lua of car 2 (skull) reloaded" \
  "$(cat "$TMP/watch.err")"
contains "--watch: car 2 raced to the flag" "finished | None" "$(second "$TMP/watched.json")"
expect_stopped "--watch" "$TMP/watched.jsonl" 4

# Good drivers race as any other: two worlds, and the script's own form of the same
out=$($PITWALL run "$TMP/race.lua" --fast --driver 2="$D/good.lua" --driver 4="$D/good.lua" \
  --results "$TMP/good.json" 2>&1)
check "two good driver worlds: exit status" 0 "$?"
contains "the board names the file's driver" "good" "$out"
check "every car finished" "4" "$(python3 -c "import json,sys; print(sum(r['status'] == 'finished' for r in json.load(open(sys.argv[1]))))" "$TMP/good.json")"
cat > "$TMP/script_form.lua" <<LUA
local race = require "pitwall.race"
race.laps { laps = 2, drivers = { [3] = "$D/loop.lua" } }
pitwall.stop()
LUA
out=$($PITWALL run "$TMP/script_form.lua" --fast --results "$TMP/form.json" 2>&1)
check "race.laps{drivers = {[3] = FILE}}: exit status" 0 "$?"
contains "the script's form makes a world too" "driver loop.lua of car 3 (thermo) is out" "$out"

# A session's driver worlds end with it: a world's own timer ticks no more once the race is over,
# though the run goes on (worlds left alive would follow every car of every later session)
cat > "$TMP/ends.lua" <<LUA
local race = require "pitwall.race"
local s = race.laps { laps = 1, drivers = { [2] = "$D/ticker.lua" }, board = false }
print(string.format("session over at %.1f", pitwall.now()))
pitwall.sleep(20)
print(string.format("run over at %.1f", pitwall.now()))
pitwall.stop()
LUA
out=$($PITWALL run "$TMP/ends.lua" --fast --no-db 2>&1)
check "a session's worlds end with it: exit status" 0 "$?"
over=$(echo "$out" | sed -n 's/.*session over at \([0-9.]*\).*/\1/p')
last=$(echo "$out" | sed -n 's/.*ticker at \([0-9.]*\).*/\1/p' | tail -1)
ticks=$(echo "$out" | grep -c "ticker at")
awk -v o="$over" -v l="$last" -v n="$ticks" 'BEGIN { exit !(n >= 3 && l <= o + 0.001) }' &&
  echo "ok: the world ticked $ticks times during the session, never after it ($last <= $over)" ||
  fail "the world's timer after the session (over at $over, last tick at $last, $ticks ticks): $out"

cat > "$TMP/missing_form.lua" <<LUA
local race = require "pitwall.race"
race.laps { laps = 1, drivers = { [2] = "$TMP/nobody.lua" } }
LUA
out=$($PITWALL run "$TMP/missing_form.lua" --fast --record "$TMP/missing.jsonl" 2>&1)
check "the script's form, a missing file: exit status 1" 1 "$?"
contains "the script's form, a missing file: named, with what a driver is" \
  "driver file $TMP/nobody.lua: no such file (a driver is a Lua file that returns a driver" "$out"
expect_stopped "the script's form, a missing file" "$TMP/missing.jsonl" 4
err=$($PITWALL run "$TMP/race.lua" --fast --driver 2="$D/good.lua" --driver-memory 0 2>&1)
contains "--driver-memory 0 is refused" "--driver-memory" "$err"

# The command line refuses what cannot be a driver before any car is connected
for bad in "x=$D/good.lua" "2" "0=$D/good.lua" "2=$TMP/missing.lua" "2=$D/broken_save.lua"; do
  err=$($PITWALL run "$TMP/race.lua" --fast --driver "$bad" 2>&1); rc=$?
  check "--driver $bad: refused (status 2)" 2 "$rc"
  contains "--driver $bad: named" "--driver $bad" "$err"
  case "$err" in *connected*) fail "--driver $bad: cars were connected first: [$err]" ;; esac
done
err=$($PITWALL run "$TMP/race.lua" --fast --driver 2="$D/good.lua" --driver 2="$D/loop.lua" 2>&1)
contains "one driver per car" "car 2 has a driver already" "$err"

# Real time: a driver that uses 45 of its 50 ms in every update takes more than its share
cat > "$TMP/lap.lua" <<'LUA'
local race = require "pitwall.race"
race.laps { laps = 1 }
pitwall.stop()
LUA
$PITWALL run "$TMP/lap.lua" --driver 2="$D/hog.lua" --results "$TMP/hog.json" \
  --record "$TMP/hog.jsonl" >/dev/null 2>"$TMP/hog.err" &
wait_bounded $!; status=$?
check "a hog in real time: exit status" 0 "$status"
contains "the hog is DNF for its share" "more than its share of the loop" "$(second "$TMP/hog.json")"
check "the others finished" "3" "$(python3 -c "import json,sys; print(sum(r['status'] == 'finished' for r in json.load(open(sys.argv[1]))))" "$TMP/hog.json")"
expect_stopped "a hog in real time" "$TMP/hog.jsonl" 4

finish
