# pitwall.alphabot{ble=ADDR} end to end (fake BlueZ with an Alphabot GATT service, real D-Bus):
# a script drives the robot over its BLE characteristics, asks the sensor, adds an obstacle and
# navigates; a robot that is not there gives a clear error.
source "$(dirname "$0")/ble_lib.sh"
start_bus
start_fake --cars 0 --alphabots 1
cat > "$TMP/ble.lua" <<'LUA'
local r = pitwall.alphabot{ble = "AB:00:00:00:00:01"}
assert(pitwall.waitUntil(function() return r.connected end, 10), "never connected: " .. tostring(r.lastError))
r.onDistance = function(_, ev) print(string.format("distance %d = %d", ev.degree, ev.distance)) end
r.onCompass = function(_, ev) print("compass " .. ev.degree) end
r.onObstacle = function(_, ev) print(string.format("obstacle %d at %d,%d", ev.id, ev.x, ev.y)) end
r.onPath = function(_, ev) print("path " .. #ev.waypoints) end
r:drive(30, -5)
r:measureDistance(90)
r:calibrateCompass()
r:addObstacle(100, 100, 20, 20)
r:navigateTo(150, 120)
pitwall.sleep(1.5)
r:drive(0, 0)
pitwall.sleep(0.2)
print("sent")
pitwall.stop()
LUA
out=$(timeout 30 "$PITWALL" run "$TMP/ble.lua" --cars 0 2>"$TMP/ble.err"); rc=$?
check "exit status" 0 "$rc"
contains "the sensor answers over SENSOR (with the 9-bit degree)" "distance 90 = " "$out"
contains "the obstacle is registered over OBSTACLE" "obstacle 1 at 100,100" "$out"
contains "the path is read from PATH_FINDING" "path " "$out"
contains "the script ran to its end" "sent" "$out"
stop_fake
summary=$(grep "^AB:00:00:00:00:01" "$TMP/fake.out")
contains "the robot was left stopped" "speed=0" "$summary"
writes=$(echo "$summary" | sed -n 's/.* writes=\([0-9]*\).*/\1/p')
[ "${writes:-0}" -ge 6 ] && echo "ok: every request reached a characteristic ($writes writes)" ||
  fail "writes: $summary"

start_fake --cars 0 --alphabots 0
cat > "$TMP/missing.lua" <<'LUA'
local ok, err = pcall(pitwall.alphabot, {ble = "AB:00:00:00:00:09"})
if ok then
  local r = err
  r.onDisconnect = function(_, ev) reason = ev.reason end
  pitwall.waitUntil(function() return r.lastError ~= nil or reason ~= nil end, 10)
  print("connected=" .. tostring(r.connected) .. " error=" .. tostring(r.lastError or reason))
else
  print("refused: " .. err)
end
pitwall.stop()
LUA
out=$(timeout 30 "$PITWALL" run "$TMP/missing.lua" --cars 0 2>"$TMP/missing.err"); rc=$?
check "a robot that is not there: the run still ends cleanly" 0 "$rc"
case "$out" in
  *"connected=false error="*AB:00:00:00:00:09*|*"refused: "*AB:00:00:00:00:09*)
    echo "ok: the error names the missing robot" ;;
  *) fail "missing robot: [$out] $(cat "$TMP/missing.err")" ;;
esac
finish
