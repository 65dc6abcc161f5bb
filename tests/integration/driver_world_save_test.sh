# A save that must not stop a car (world:tryReload, docs/drivers.md "A save brings it back"; the
# code editor's save of issue 39): mid-race car 2's driver file is saved broken — a syntax error,
# a main chunk that raises, one that loops, one that allocates without bound, one that calls
# os.exit, one whose driver has no update — and each save is refused with the engine's sentence
# (the file and line where there is one), while the version already driving goes on: same
# version, not out, its car still driven. A good save then replaces it (version +1, started by
# the director at the new speed) and car 2 finishes the race. (--driver-memory 16 and
# --driver-budget 0.5: the growth meets its cap before its budget — 16 MB of strings took 50 to
# 105 ms of CPU time on the 2-core VMs here, past the default budget of 50 ms.)
source "$(dirname "$0")/lib.sh"

cp "$SRC/tests/integration/drivers/good.lua" "$TMP/student.lua"
cat > "$TMP/race.lua" <<'LUA'
local race = require "pitwall.race"
local saved = false
local function write(path, text)
  local f = assert(io.open(path, "w"))
  f:write(text)
  f:close()
end
race.laps { laps = 4, onLap = function(car, lap, session)
  local second = pitwall.cars()[2]
  if car == second and saved then print(string.format("car 2 lap %d at %d mm/s", lap.number, car.targetSpeed)) end
  if saved or car.number ~= 1 then return end
  saved = true
  local w = session:entry(second).driver.world
  local v0 = w.version
  print(string.format("before: version %d, car 2 at %d mm/s", v0, second.targetSpeed))
  write(w.file, "return {\n  update = function(self, car)\n    car:setSpeed(\n  end,\n}\n")
  local ok, why = w:tryReload()
  print(string.format("syntax: %s | %s | version %d | out %s | %d mm/s", tostring(ok), tostring(why),
    w.version, tostring(w.failure), second.targetSpeed))
  write(w.file, "local x = nil\nreturn x.driver\n")
  ok, why = w:tryReload()
  print(string.format("raises: %s | %s | version %d | out %s", tostring(ok), tostring(why), w.version,
    tostring(w.failure)))
  for _, hostile in ipairs {
    { "loops", "while true do end\n" },
    { "grows", "local t = {}\nwhile true do t[#t + 1] = string.rep('x', 1e6) .. #t end\n" },
    { "exits", "os.exit(3)\n" },
    { "no update", "return { name = 'lazy' }\n" },
  } do
    write(w.file, hostile[2])
    ok, why = w:tryReload()
    print(string.format("%s: %s | %s | version %d | out %s", hostile[1], tostring(ok), tostring(why),
      w.version, tostring(w.failure)))
  end
  write(w.file, "local cruiser = require 'pitwall.drivers.cruiser'\nreturn { new = function() return cruiser.new { speed = 650 } end }\n")
  ok, why = w:tryReload()
  print(string.format("good: %s | %s | version %d | out %s", tostring(ok), tostring(why), w.version,
    tostring(w.failure)))
end, results = os.getenv("RESULTS") }
pitwall.stop()
LUA

out=$(RESULTS="$TMP/results.json" "$PITWALL" run "$TMP/race.lua" --fast --no-db --driver-memory 16 --driver-budget 0.5 --driver 2="$TMP/student.lua" 2>"$TMP/err"); rc=$?
echo "$out"
check "exit status" 0 "$rc"
contains "before: the first version drives" "before: version 1, car 2 at 800 mm/s" "$out"
contains "a syntax error is refused with its file and line" "syntax: false | its file does not load: " "$out"
contains "... naming the line" "student.lua:4:" "$(echo "$out" | grep '^syntax:')"
contains "... and the version driving goes on" "| version 1 | out nil | 800 mm/s" "$(echo "$out" | grep '^syntax:')"
contains "a main chunk that raises is refused with its line" "student.lua:2: attempt to index a nil value" "$(echo "$out" | grep '^raises:')"
contains "... and the version driving goes on" "| version 1 | out nil" "$(echo "$out" | grep '^raises:')"
for hostile in loops grows exits "no update"; do
  line=$(echo "$out" | grep "^$hostile:")
  contains "a save that $hostile is refused, the version driving goes on" "$hostile: false | " "$line"
  contains "... same version, not out" "| version 1 | out nil" "$line"
done
contains "the loop is refused by its budget" "budget" "$(echo "$out" | grep '^loops:')"
contains "the growth is refused by its memory cap" "memory limit" "$(echo "$out" | grep '^grows:')"
contains "os.exit is refused with a sentence" "os.exit" "$(echo "$out" | grep '^exits:')"
contains "a driver without update is refused with a sentence" "must return a driver" "$(echo "$out" | grep '^no update:')"
contains "a good save replaces it" "good: true | nil | version 2 | out nil" "$out"
contains "the new version drives car 2 (started by the director)" "at 650 mm/s" "$(echo "$out" | grep '^car 2 lap')"
status=$(python3 -c "import json,sys; r=[x for x in json.load(open(sys.argv[1])) if x['number']==2][0]; print(r['status'], r['finished'])" "$TMP/results.json")
check "car 2 finished the race" "finished True" "$status"
[ "$FAILURES" -gt 0 ] && sed 's/^/  | /' "$TMP/err" | tail -30
finish
