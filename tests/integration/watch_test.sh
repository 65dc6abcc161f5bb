# pitwall run --watch as a user runs it: save a new version and it takes over the driving cars;
# a broken save is refused and the running version carries on; a script that dies waits for a fix.
source "$(dirname "$0")/lib.sh"

# count FILE PATTERN
count() { grep -cE "$2" "$1" 2>/dev/null || true; }

version() {  # version N SPEED: a script that prints "vN tick n=…" five times a second
  cat <<LUA
local p = pitwall.persist
p.n = p.n or 0
local car = pitwall.cars()[1]
car:setSpeed($2)
pitwall.every(0.2, function()
  p.n = p.n + 1
  print(string.format("v$1 tick n=%d speed=%d", p.n, car.speed))
end)
LUA
}

mkdir -p "$TMP/proj"
S="$TMP/proj/race.lua"
version 1 400 > "$S"
$PITWALL run "$S" --watch --cars 1 >"$TMP/out" 2>"$TMP/err" &
PID=$!
wait_for "$TMP/out" "^v1 tick" && echo "ok: version 1 runs" || fail "version 1 never ticked: $(cat "$TMP/err")"
contains "says it watches" "watching" "$(cat "$TMP/err")"

# Saved in place: version 2 takes over; the count in pitwall.persist carries on from version 1.
version 2 800 > "$S"
wait_for "$TMP/out" "^v2 tick" && echo "ok: version 2 took over" || fail "no v2: $(cat "$TMP/err")"
first_v2=$(grep -m1 "^v2 tick" "$TMP/out" | sed 's/.*n=\([0-9]*\).*/\1/')
last_v1=$(grep "^v1 tick" "$TMP/out" | tail -1 | sed 's/.*n=\([0-9]*\).*/\1/')
check "persisted count continues" "$((last_v1 + 1))" "$first_v2"
contains "the log says which file changed" "race.lua changed: version 2 took over" "$(cat "$TMP/err")"
wait_for "$TMP/out" "^v2 tick n=[0-9]+ speed=(7[5-9][0-9]|8[0-4][0-9])" &&
  echo "ok: the car drives at version 2's speed" || fail "speed: $(tail -3 "$TMP/out")"

# A save that does not compile: refused with file and line; version 2 carries on.
printf 'local car = pitwall.cars()[1]\ncar:setSpeed(100)\nfor\n' > "$S"
wait_for "$TMP/err" "not started" && echo "ok: the broken version is refused" || fail "no refusal"
contains "refusal names file and line" "race.lua:4:" "$(cat "$TMP/err")"
contains "the old version carries on" "running version carries on" "$(cat "$TMP/err")"
before=$(count "$TMP/out" "^v2 tick")
wait_for "$TMP/out" "^v2 tick n=$(( $(grep "^v2 tick" "$TMP/out" | tail -1 | sed 's/.*n=\([0-9]*\).*/\1/') + 2 ))" &&
  echo "ok: version 2 still ticks after the refusal" || fail "v2 stopped ticking"

# An editor's atomic save (write elsewhere, rename over): version 3.
version 3 600 > "$TMP/proj/.race.lua.swp"
mv "$TMP/proj/.race.lua.swp" "$S"
wait_for "$TMP/out" "^v3 tick" && echo "ok: an atomic save reloads" || fail "no v3 after rename"
check "no v2 tick after v3 began" "" "$(sed -n '/^v3 tick/,$p' "$TMP/out" | grep '^v2 tick')"

# A module the script requires: saving it reloads too.
cat > "$TMP/proj/speeds.lua" <<'LUA'
return {fast = 700}
LUA
cat > "$S" <<'LUA'
local speeds = require "speeds"
pitwall.cars()[1]:setSpeed(speeds.fast)
pitwall.every(0.2, function() print("v4 tick fast=" .. speeds.fast) end)
LUA
wait_for "$TMP/out" "^v4 tick fast=700" && echo "ok: version 4 requires a module" || fail "no v4"
printf 'return {fast = 650}\n' > "$TMP/proj/speeds.lua"
wait_for "$TMP/out" "^v4 tick fast=650" && echo "ok: saving the module reloads" || fail "module save"

# A version that dies after it started: its cars are stopped and the run waits for a fix.
cat > "$S" <<'LUA'
pitwall.cars()[1]:setSpeed(500)
pitwall.sleep(0.3)
error("gave up")
LUA
wait_for "$TMP/err" "stopped with an error" && echo "ok: a dying version stops its cars" ||
  fail "no death notice: $(tail -5 "$TMP/err")"
contains "the error names the line" "race.lua:3: gave up" "$(cat "$TMP/err")"
kill -0 $PID 2>/dev/null && echo "ok: pitwall still runs" || fail "pitwall exited"
version 5 500 > "$S"
wait_for "$TMP/out" "^v5 tick" && echo "ok: the fix runs" || fail "no v5"

kill -INT $PID
wait $PID
check "Ctrl-C exit status" 130 "$?"

# A first version that does not load: reported, and the run waits for the fix.
printf 'for\n' > "$S"
$PITWALL run "$S" --watch --cars 1 >"$TMP/out2" 2>"$TMP/err2" &
PID=$!
wait_for "$TMP/err2" "waiting for the script" && echo "ok: a broken first version waits" ||
  fail "no wait: $(cat "$TMP/err2")"
version 6 500 > "$S"
wait_for "$TMP/out2" "^v6 tick" && echo "ok: and runs once fixed" || fail "no v6: $(cat "$TMP/err2")"
kill -TERM $PID
wait $PID
check "SIGTERM exit status" 130 "$?"

finish
