-- An Alphabot explores its room: it turns its distance sensor all the way round, maps what it
-- sees, registers the obstacles it found, and navigates to a target around them.
--
-- It talks to a robot over WLAN (TCP), in real time. To try it on the simulated robot:
--   pitwall sim-robot alphabot --listen 127.0.0.1:4000 &
--   ALPHABOT_PORT=4000 pitwall run examples/alphabot_explore.lua
-- ALPHABOT_HOST (default 127.0.0.1), ALPHABOT_PORT, ALPHABOT_TARGET ("x,y" in cm, default 350,150).

local host = os.getenv("ALPHABOT_HOST") or "127.0.0.1"
local port = tonumber(os.getenv("ALPHABOT_PORT") or "")
if not port or pitwall.virtualTime then
  -- `pitwall run --fast` (and the examples test) has no robot to talk to.
  print("alphabot_explore: set ALPHABOT_PORT to a robot's port (e.g. one started with "
        .. "`pitwall sim-robot alphabot`) and run without --fast")
  pitwall.stop()
  return
end
local tx, ty = (os.getenv("ALPHABOT_TARGET") or "350,150"):match("^(%-?%d+),(%-?%d+)$")
tx, ty = tonumber(tx), tonumber(ty)

local robot = pitwall.alphabot{host = host, port = port}
if not pitwall.waitUntil(function() return robot.connected end, 5) then
  error("no Alphabot at " .. host .. ":" .. port .. ": " .. tostring(robot.lastError))
end
robot.onDisconnect = function(_, ev) print("lost the robot: " .. ev.reason) end

-- Where am I, which way do I face?
robot:set{positioning = true, collisionAvoidance = true}
robot:calibrateCompass()
assert(pitwall.waitUntil(function() return robot.x and robot.heading end, 3), "no position")
local x0, y0, heading = robot.x, robot.y, robot.heading
print(string.format("at (%d, %d), heading %d°", x0, y0, heading))

-- 1. Sweep the sensor: one reading every 5°, all round.
local hits = {}
robot.onDistance = function(_, ev)
  local a = math.rad(heading + ev.degree)
  hits[#hits + 1] = {degree = ev.degree, x = x0 + ev.distance * math.cos(a),
                     y = y0 + ev.distance * math.sin(a)}
end
local readings = 0
for degree = -180, 175, 5 do
  robot:measureDistance(degree)
  readings = readings + 1
end
assert(pitwall.waitUntil(function() return #hits == readings end, 5), "sensor readings missing")
table.sort(hits, function(a, b) return a.degree < b.degree end)

-- 2. Walls are the outermost hits; everything seen inside them is an obstacle. Neighbouring
-- obstacle hits form one obstacle; we saw its near face only, so we give it some depth away
-- from the robot.
local minX, maxX, minY, maxY = math.huge, -math.huge, math.huge, -math.huge
for _, h in ipairs(hits) do
  minX, maxX = math.min(minX, h.x), math.max(maxX, h.x)
  minY, maxY = math.min(minY, h.y), math.max(maxY, h.y)
end
local function isWall(h)
  return h.x < minX + 3 or h.x > maxX - 3 or h.y < minY + 3 or h.y > maxY - 3
end
local clusters, current = {}, nil
for _, h in ipairs(hits) do
  if isWall(h) then
    current = nil
  else
    if not current or math.abs(h.x - current.last.x) + math.abs(h.y - current.last.y) > 25 then
      current = {x1 = h.x, x2 = h.x, y1 = h.y, y2 = h.y}
      clusters[#clusters + 1] = current
    end
    current.x1, current.x2 = math.min(current.x1, h.x), math.max(current.x2, h.x)
    current.y1, current.y2 = math.min(current.y1, h.y), math.max(current.y2, h.y)
    current.last = h
  end
end
local printf = function(...) print(string.format(...)) end
printf("room seen: x %d..%d, y %d..%d cm; %d obstacle(s) found", math.floor(minX + 0.5),
       math.floor(maxX + 0.5), math.floor(minY + 0.5), math.floor(maxY + 0.5), #clusters)

-- 3. Register them, 5 cm larger all round (a reading every 5° may miss a corner): the robot's
-- path finder plans around what is registered.
local registered = 0
robot.onObstacle = function(_, ev)
  registered = registered + 1
  printf("obstacle %d registered at (%d, %d), %d x %d cm", ev.id, ev.x, ev.y, ev.width, ev.height)
end
robot:clearObstacles()
local depth = 40
for _, c in ipairs(clusters) do
  local cx, cy = (c.x1 + c.x2) / 2, (c.y1 + c.y2) / 2
  local x1, x2, y1, y2 = c.x1, c.x2, c.y1, c.y2
  if c.x2 - c.x1 < c.y2 - c.y1 then   -- a face across x: extend away from the robot
    if cx > x0 then x2 = x2 + depth else x1 = x1 - depth end
  else
    if cy > y0 then y2 = y2 + depth else y1 = y1 - depth end
  end
  x1, y1, x2, y2 = x1 - 5, y1 - 5, x2 + 5, y2 + 5
  robot:addObstacle(math.floor(x1), math.floor(y1), math.ceil(x2 - x1), math.ceil(y2 - y1))
end
assert(pitwall.waitUntil(function() return registered == #clusters end, 3), "not registered")

-- 4. Navigate to the target around them.
local path
robot.onPath = function(_, ev) path = pitwall.copy(ev.waypoints) end
robot:navigateTo(tx, ty)
assert(pitwall.waitUntil(function() return path end, 3), "no path")
if #path == 0 then
  printf("the target (%d, %d) cannot be reached", tx, ty)
  pitwall.stop()
  return
end
local legs = {}
for _, w in ipairs(path) do legs[#legs + 1] = string.format("(%d, %d)", w.x, w.y) end
print("path: " .. table.concat(legs, " -> "))
-- The robot reports its position as it drives; when the reports stop short of the target, it
-- stopped on the way (collision avoidance saw something the map does not have).
local started, lastMove = pitwall.now(), pitwall.now()
robot.onPosition = function() lastMove = pitwall.now() end
local arrived = pitwall.waitUntil(function()
  return (robot.x == tx and robot.y == ty) or pitwall.now() - lastMove > 2
end, 120) and robot.x == tx and robot.y == ty
if arrived then
  printf("arrived at (%d, %d) after %.1f s", robot.x, robot.y, pitwall.now() - started)
else
  printf("did not arrive: at (%s, %s)", tostring(robot.x), tostring(robot.y))
end
pitwall.stop()
