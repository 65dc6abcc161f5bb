# pitwall test as a user runs it: results per scenario, the closing line, exit statuses, failure
# messages with file, line and the values compared.
source "$(dirname "$0")/lib.sh"

mkdir -p "$TMP/suite"
cat > "$TMP/suite/good_test.lua" <<'LUA'
local sim = require "pitwall.sim"
local car = sim.addCar {}
car:setSpeed(500)
sim.run(5)
expect.gt(sim.truth(car).speed, 400)
LUA
cat > "$TMP/suite/bad_test.lua" <<'LUA'
local sim = require "pitwall.sim"
local car = sim.addCar {}
sim.run(1)
expect.eq(car.speed, 123, "speed")
LUA
cat > "$TMP/suite/callback_test.lua" <<'LUA'
local sim = require "pitwall.sim"
local car = sim.addCar {}
car.onPosition = function() assert(false, "asserted in a callback") end
car:setSpeed(500)
sim.run(5)
LUA
cat > "$TMP/suite/endless_test.lua" <<'LUA'
while true do pitwall.sleep(1) end
LUA
cat > "$TMP/suite/yields_test.lua" <<'LUA'
coroutine.yield()
LUA
echo "not a test" > "$TMP/suite/helper.lua"

out=$($PITWALL test "$TMP/suite" --timeout 30 2>&1); rc=$?
check "exit status with failures" 1 "$rc"
check "closing line" "1 passed, 4 failed" "$(echo "$out" | tail -1)"
contains "a bare yield in the main chunk fails at once" "yielded without pitwall.sleep" "$out"
case "$out" in *"yields_test.lua (0.1 s simulated"*) echo "ok: it fails without waiting for the timeout" ;; *) fail "the bare yield was not reported at once: $out" ;; esac
contains "passing scenario listed" "ok    $TMP/suite/good_test.lua" "$out"
contains "failed expectation names file, line and values" "bad_test.lua:4: speed: expected 123, got 0" "$out"
contains "an assert in a callback fails the scenario" "asserted in a callback" "$out"
contains "a scenario that never ends times out" "still running after 30 s of virtual time" "$out"
case "$out" in *helper.lua*) fail "a file not named *_test.lua was run" ;; *) echo "ok: only *_test.lua files run" ;; esac

out=$($PITWALL test "$TMP/suite/good_test.lua" 2>&1); rc=$?
check "exit status when all pass" 0 "$rc"
check "closing line when all pass" "1 passed, 0 failed" "$(echo "$out" | tail -1)"

mkdir -p "$TMP/empty"
err=$($PITWALL test "$TMP/empty" 2>&1); rc=$?
check "empty folder exit status" 2 "$rc"
contains "empty folder is named" "$TMP/empty" "$err"
finish
