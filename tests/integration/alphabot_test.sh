# The Alphabot over WLAN as a user meets it: decode/encode golden outputs and errors, the
# simulated robot (sim-robot alphabot) over loopback with Lua scripts: every request answered,
# navigation around obstacles and to an unreachable target, collision avoidance, a robot that
# disappears and comes back, malformed bytes, and the example. Run as:
#   bash alphabot_test.sh PITWALL SRC FAKE_BLUEZ
source "$(dirname "$0")/lib.sh"
PIDS=()
cleanup() {
  for pid in "${PIDS[@]}"; do kill "$pid" 2>/dev/null; done
  rm -rf "$TMP"
}
trap cleanup EXIT

# startRobot NAME [ARGS…]: a simulated robot on a free port (or --listen in ARGS); sets PORT.
startRobot() {
  local name=$1
  shift
  $PITWALL sim-robot alphabot "$@" >"$TMP/$name.out" 2>"$TMP/$name.err" &
  PIDS+=($!)
  ROBOT_PID=$!
  wait_for "$TMP/$name.out" "listening on" 30 || { fail "$name: sim-robot did not start: $(cat "$TMP/$name.err")"; return 1; }
  PORT=$(sed -n 's/^listening on .*:\([0-9]*\)$/\1/p' "$TMP/$name.out")
}

# ---- decode / encode ----
enc() { $PITWALL encode alphabot "$@" 2>&1; }
check "encode drive" "01 32 f6" "$(enc drive 50 -10)"
check "encode measure-distance" "02 5a 00" "$(enc measure-distance 90)"
check "encode toggles by name" "05 30 00" "$(enc toggles collisionAvoidance,positioning)"
check "encode ping" "06 39 30 00 00 00 00 00 00" "$(enc ping 12345)"
check "encode anchor" "07 01 64 00 c8 00" "$(enc anchor 1 100 200)"
check "encode navigate" "08 2c 01 96 00" "$(enc navigate 300 150)"
check "encode add-obstacle" "09 0a 00 14 00 1e 00 28 00" "$(enc add-obstacle 10 20 30 40)"
check "encode remove-obstacle" "0a 03" "$(enc remove-obstacle 3)"
check "encode remove-obstacle-at" "0b 0a 00 14 00" "$(enc remove-obstacle-at 10 20)"
check "encode clear-obstacles" "0c" "$(enc clear-obstacles)"
check "encode calibrate-steering" "03" "$(enc calibrate-steering)"
check "encode calibrate-compass" "04" "$(enc calibrate-compass)"
out=$(enc drive 200 0); rc=$?
check "encode out of range exits 2" 2 "$rc"
contains "encode out of range names the range" "speed 200 is out of range -128..127" "$out"
out=$(enc toggles warpDrive); contains "encode unknown toggle lists the names" "known: compassCalibration, invite" "$out"
out=$(enc fly); contains "encode unknown message" "unknown alphabot message 'fly'" "$out"

dec() { $PITWALL decode alphabot "$@" 2>&1; }
check "decode distance" '{"degree":90,"distance":130,"name":"distance","packet":"0x81"}' "$(dec 81 5a 00 82 00)"
check "decode path" '{"name":"path","packet":"0x83","waypoints":[{"x":10,"y":20},{"x":30,"y":40}]}' \
  "$(dec "83 02 0a 00 14 00 1e 00 28 00")"
check "decode 0xC0 as toggles" '{"name":"toggles","packet":"0x05","toggles":{"logging":0,"on":["collisionAvoidance"],"settings":16}}' \
  "$(dec c0:10:00)"
check "decode obstacle registered" '{"height":100,"id":7,"name":"obstacle-registered","packet":"0x86","width":40,"x":180,"y":100}' \
  "$(dec 8607b40064002800 6400)"
out=$(dec 86 01 0a 00); rc=$?
check "decode short packet exits 2" 2 "$rc"
check "decode short packet names id and lengths" "pitwall decode: packet 0x86 (obstacle-registered) is 4 byte(s), expected 10" "$out"
out=$(dec 42 00); rc=$?
check "decode unknown id exits 2" 2 "$rc"
contains "decode unknown id" "unknown packet id 0x42" "$out"
out=$(dec 83 02 0a 00); contains "decode path with too few waypoints" "expected 10 (from its count)" "$out"

# ---- sim-robot options ----
out=$($PITWALL sim-robot alphabot --listen nowhere 2>&1); rc=$?
check "bad --listen exits 2" 2 "$rc"
contains "bad --listen says why" "is not HOST:PORT" "$out"
printf 'room 200 100\nwall 1 2 3\n' >"$TMP/bad.room"
out=$($PITWALL sim-robot alphabot --room "$TMP/bad.room" 2>&1); rc=$?
check "bad room file exits 2" 2 "$rc"
contains "bad room file names the line" "bad.room:2: unknown statement 'wall'" "$out"

# ---- every request answered, over loopback ----
startRobot main
cat >"$TMP/requests.lua" <<'LUA'
local r = pitwall.alphabot{host = "127.0.0.1", port = tonumber(os.getenv("PORT"))}
assert(pitwall.waitUntil(function() return r.connected end, 3), "no connection")
local d = {}
r.onDistance = function(_, ev) d[ev.degree] = ev.distance end
r.onCompass = function(_, ev) print("compass " .. ev.degree) end
r.onPing = function(_, ev) print("ping " .. (ev.rtt >= 0 and ev.rtt < 1 and "ok" or ev.rtt)) end
r.onObstacle = function(_, ev) print(string.format("obstacle %d %d,%d %dx%d", ev.id, ev.x, ev.y, ev.width, ev.height)) end
r.onPosition = function(_, ev) pos = ev end
r.onPath = function(_, ev) path = ev end
for _, deg in ipairs{0, 90, 180, -90} do r:measureDistance(deg) end
r:calibrateCompass(); r:ping(); r:calibrateSteering()
r:set{positioning = true}
r:setAnchor(4, 400, 300)
assert(pitwall.waitUntil(function() return d[-90] and pos end, 3), "no answers")
print(string.format("distance 0=%d 90=%d 180=%d -90=%d", d[0], d[90], d[180], d[-90]))
print(string.format("position %d,%d", pos.x, pos.y))
-- A registered obstacle bends the path; removed, the path is straight again.
r:addObstacle(100, 100, 20, 100)
r:navigateTo(150, 150)
assert(pitwall.waitUntil(function() return path end, 3)); print("path with obstacle " .. (#path.waypoints > 1 and "bends" or "straight"))
r:drive(0, 0)  -- takes over from navigation
path = nil; r:removeObstacle(1); r:navigateTo(150, 150)
assert(pitwall.waitUntil(function() return path end, 3)); print("path legs after remove " .. #path.waypoints)
r:drive(0, 0)
r:addObstacle(100, 100, 20, 100); r:addObstacle(0, 0, 5, 5)
path = nil; r:removeObstacle(110, 150); r:removeObstacle(3); r:navigateTo(150, 150)
assert(pitwall.waitUntil(function() return path end, 3)); print("path legs after remove-at " .. #path.waypoints)
r:drive(0, 0)
r:addObstacle(100, 100, 20, 100); r:addObstacle(100, 0, 20, 90)
path = nil; r:clearObstacles(); r:navigateTo(150, 150)
assert(pitwall.waitUntil(function() return path end, 3)); print("path legs after clear " .. #path.waypoints)
pitwall.stop()
LUA
out=$(PORT=$PORT timeout 20 $PITWALL run "$TMP/requests.lua" --cars 0 2>"$TMP/requests.err"); rc=$?
check "requests script exit status" 0 "$rc"
contains "distances against the walls and the box" "distance 0=130 90=150 180=50 -90=150" "$out"
contains "position (positioning on)" "position 50,150" "$out"
contains "compass after calibration" "compass 0" "$out"
contains "ping echoed" "ping ok" "$out"
contains "obstacle registered with an id" "obstacle 1 100,100 20x100" "$out"
contains "a registered obstacle bends the path" "path with obstacle bends" "$out"
contains "removed by id: straight" "path legs after remove 1" "$out"
contains "removed by position: straight" "path legs after remove-at 1" "$out"
contains "cleared: straight" "path legs after clear 1" "$out"

# ---- navigation around obstacles, and an unreachable target ----
cat >"$TMP/navigate.lua" <<'LUA'
local r = pitwall.alphabot{host = "127.0.0.1", port = tonumber(os.getenv("PORT"))}
assert(pitwall.waitUntil(function() return r.connected end, 3), "no connection")
r:clearObstacles()
r:addObstacle(175, 95, 50, 110)  -- the default room's box, with a margin
r.onPath = function(_, ev) path = pitwall.copy(ev.waypoints) end
r:navigateTo(350, 150)
assert(pitwall.waitUntil(function() return path end, 3), "no path")
print("waypoints " .. #path .. " last " .. path[#path].x .. "," .. path[#path].y)
print(pitwall.waitUntil(function() return r.x == 350 and r.y == 150 end, 30) and "arrived" or "not arrived")
path = nil
r:addObstacle(300, 0, 20, 300)  -- a wall across the room
r:navigateTo(50, 150)
assert(pitwall.waitUntil(function() return path end, 3), "no path")
print("unreachable waypoints " .. #path)
pitwall.stop()
LUA
out=$(PORT=$PORT timeout 40 $PITWALL run "$TMP/navigate.lua" --cars 0 2>&1); rc=$?
check "navigate script exit status" 0 "$rc"
contains "path around the box ends at the target" "last 350,150" "$out"
case "$out" in *"waypoints 1 "*) fail "the path went straight through the box: $out" ;; *) echo "ok: the path bends" ;; esac
contains "navigation reaches the target" "arrived" "$out"
contains "unreachable target: empty path" "unreachable waypoints 0" "$out"
kill "$ROBOT_PID" 2>/dev/null; wait "$ROBOT_PID" 2>/dev/null

# ---- collision avoidance (a small room: the robot meets the wall quickly) ----
printf 'room 120 100\nrobot 30 50 0\n' >"$TMP/small.room"
startRobot small --room "$TMP/small.room"
cat >"$TMP/avoid.lua" <<'LUA'
local r = pitwall.alphabot{host = "127.0.0.1", port = tonumber(os.getenv("PORT"))}
assert(pitwall.waitUntil(function() return r.connected end, 3), "no connection")
r:set{collisionAvoidance = true, positioning = true}
r:drive(100, 0)
local last, still = nil, 0
r.onDistance = function(_, ev) gap = ev.distance end
-- Stopped: the position has not changed for 0.5 s.
assert(pitwall.waitUntil(function()
  if r.x == last then still = still + 1 else still, last = 0, r.x end
  return still > 50
end, 10), "never stopped")
r:measureDistance(0)
assert(pitwall.waitUntil(function() return gap end, 3))
print("stopped with " .. (gap - 10) .. " cm to spare")
pitwall.stop()
LUA
out=$(PORT=$PORT timeout 20 $PITWALL run "$TMP/avoid.lua" --cars 0 2>&1); rc=$?
check "avoidance script exit status" 0 "$rc"
spare=$(echo "$out" | sed -n 's/^stopped with \([0-9-]*\) cm to spare$/\1/p')
if [ -n "$spare" ] && [ "$spare" -ge 3 ]; then echo "ok: stopped short of the wall ($spare cm)"; else fail "collision avoidance: $out"; fi
kill "$ROBOT_PID" 2>/dev/null; wait "$ROBOT_PID" 2>/dev/null

# ---- a robot that disappears mid-run, and comes back ----
startRobot vanish
cat >"$TMP/vanish.lua" <<'LUA'
local r = pitwall.alphabot{host = "127.0.0.1", port = tonumber(os.getenv("PORT"))}
print("connected"); io.stdout:flush()  -- ready when made: connected already
r.onConnect = function() print("connected again"); io.stdout:flush() end
r.onDisconnect = function(_, ev) print("disconnected: " .. ev.reason); io.stdout:flush() end
assert(pitwall.waitUntil(function() return not r.connected end, 10), "never lost")
local ok, e = pcall(r.drive, r, 10, 0)
print("drive while lost: " .. tostring(e)); io.stdout:flush()
assert(pitwall.waitUntil(function() return r.connected end, 15), "never came back")
r:ping()
assert(pitwall.waitUntil(function() return r.lastPing end, 3), "no ping answer")
print("back, ping answered")
pitwall.stop()
LUA
PORT=$PORT timeout 40 $PITWALL run "$TMP/vanish.lua" --cars 0 >"$TMP/vanish.run" 2>"$TMP/vanish.log" &
RUN_PID=$!
PIDS+=($RUN_PID)
wait_for "$TMP/vanish.run" "^connected" 5 || fail "vanish: never connected"
kill -9 "$ROBOT_PID"; wait "$ROBOT_PID" 2>/dev/null
wait_for "$TMP/vanish.run" "drive while lost" 5 || fail "vanish: the script was not told"
startRobot vanish2 --listen "127.0.0.1:$PORT"
wait "$RUN_PID"; rc=$?
out=$(cat "$TMP/vanish.run")
check "vanish script exit status" 0 "$rc"
contains "onDisconnect with the reason" "disconnected: the robot closed the connection" "$out"
contains "a command while lost is refused, naming why" "nothing sent: tcp:127.0.0.1:$PORT: not connected" "$out"
contains "reconnected after the robot came back" "back, ping answered" "$out"
contains "the log says it was lost" "lost: the robot closed the connection; retrying" "$(cat "$TMP/vanish.log")"
kill "$ROBOT_PID" 2>/dev/null; wait "$ROBOT_PID" 2>/dev/null

# ---- ready when made: the line after pitwall.alphabot{…} drives; an unreachable robot errs ----
startRobot ready
cat >"$TMP/ready.lua" <<'LUA'
local r = pitwall.alphabot{host = "127.0.0.1", port = tonumber(os.getenv("PORT"))}
r:drive(40, 0)
pitwall.sleep(0.3)
print("drove: " .. tostring(r.connected))
pitwall.stop()
LUA
out=$(PORT=$PORT timeout 20 $PITWALL run "$TMP/ready.lua" --cars 0 2>&1); rc=$?
check "ready when made: exit status" 0 "$rc"
contains "ready when made: the first command went" "drove: true" "$out"
kill "$ROBOT_PID" 2>/dev/null; wait "$ROBOT_PID" 2>/dev/null
out=$(PORT=$PORT timeout 20 $PITWALL run "$TMP/ready.lua" --cars 0 2>&1); rc=$?
[ "$rc" -ne 0 ] && echo "ok: an unreachable robot fails the script" || fail "an unreachable robot: exit status 0"
contains "an unreachable robot: a clear error" "alphabot tcp:127.0.0.1:$PORT is not connected after 3 s (connectTimeout)" "$out"

# ---- a robot that sends malformed bytes (a fake one in Python) ----
if command -v python3 >/dev/null; then
  cat >"$TMP/fake.py" <<'PY'
import socket, sys
s = socket.socket(); s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
s.bind(("127.0.0.1", 0)); s.listen(1)
print("listening on 127.0.0.1:%d" % s.getsockname()[1], flush=True)
c, _ = s.accept()
c.sendall(bytes([0x42, 0x13, 0x81, 0x5a, 0x00, 0x82, 0x00]))  # garbage, then a distance
c.recv(100)  # wait for the script's goodbye (the stop on close)
PY
  python3 "$TMP/fake.py" >"$TMP/fake.out" &
  PIDS+=($!)
  # (30 s: on a loaded machine Python itself can take seconds to start; the wait ends when it says)
  wait_for "$TMP/fake.out" "listening on" 30 || fail "the fake robot did not start within 30 s"
  FPORT=$(sed -n 's/^listening on .*:\([0-9]*\)$/\1/p' "$TMP/fake.out")
  cat >"$TMP/malformed.lua" <<'LUA'
-- made in a callback, the robot returns at once: the handlers are set before the robot's
-- first bytes (in a task it would be connected, and the bytes read, before the next line)
pitwall.after(0, function()
  r = pitwall.alphabot{host = "127.0.0.1", port = tonumber(os.getenv("PORT"))}
  r.onMalformed = function(_, ev) print("malformed: " .. ev.error) end
  r.onDistance = function(_, ev) print("distance " .. ev.degree .. " " .. ev.distance) end
end)
assert(pitwall.waitUntil(function() return r end, 1))
assert(pitwall.waitUntil(function() return r.malformed == 1 and r.connected end, 5))
pitwall.sleep(0.2)
print("still connected: " .. tostring(r.connected))
pitwall.stop()
LUA
  out=$(PORT=$FPORT timeout 20 $PITWALL run "$TMP/malformed.lua" --cars 0 2>"$TMP/malformed.log"); rc=$?
  check "malformed script exit status" 0 "$rc"
  contains "onMalformed names the id" "malformed: unknown packet id 0x42" "$out"
  contains "the stream resynchronises" "distance 90 130" "$out"
  contains "the link stays up" "still connected: true" "$out"
  contains "the log warns" "malformed packet: unknown packet id 0x42" "$(cat "$TMP/malformed.log")"
else
  echo "skip: no python3 for the malformed-bytes robot"
fi

# ---- the example, against the simulated robot ----
startRobot example
out=$(ALPHABOT_PORT=$PORT timeout 60 $PITWALL run "$SRC/examples/alphabot_explore.lua" --cars 0 2>&1); rc=$?
check "example exit status" 0 "$rc"
contains "example found the box" "1 obstacle(s) found" "$out"
contains "example printed the path" "path: (" "$out"
contains "example arrived" "arrived at (350, 150)" "$out"
kill "$ROBOT_PID" 2>/dev/null; wait "$ROBOT_PID" 2>/dev/null
finish
