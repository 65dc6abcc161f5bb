-- A user-written driver with state survives a swap: each save of the script makes a new driver
-- for every car, which takes over (driver:takeover) what the old one handed over
-- (driver:handover) — here a count of its updates and of the versions it drove in — at the next
-- update, without a stop or a speed gap. A driver without takeover is started instead.
-- tags: drivers reload
local sim = require "pitwall.sim"

local out = os.tmpname()
local SOURCE = [[
local race = require "pitwall.race"
local Counter = { name = "counter" }
Counter.__index = Counter
function Counter.new(speed)
  return setmetatable({ speed = speed, updates = 0, versions = 1 }, Counter)
end
function Counter:update(car, ctx)
  self.updates = self.updates + 1
  if car.targetSpeed ~= self.speed then car:setSpeed(self.speed, 2000) end
end
function Counter:handover() return { updates = self.updates, versions = self.versions } end
function Counter:takeover(car, ctx, state, from)
  self.updates, self.versions, self.from = state.updates, state.versions + 1, from
end
function Counter:finish(car, ctx)
  local f = assert(io.open(OUT .. car.name, "w"))
  f:write(string.format("%d %d %s %d", self.updates, self.versions, tostring(self.from),
    self.started or 0))
  f:close()
end
-- the plain driver has no takeover: a new version starts it
function Counter:start() self.started = (self.started or 0) + 1 end
if not TAKEOVER then Counter.takeover = nil; Counter.handover = nil end
local r = race.laps { laps = 3, drivers = function(car, i) return Counter.new(SPEED + 100 * i) end,
  board = false, results = false }
pitwall.stop()
]]
local function version(speed, takeover)
  return string.format("local OUT, SPEED, TAKEOVER = %q, %d, %s\n", out, speed, tostring(takeover))
    .. SOURCE
end

local cars = {}
for i = 1, 2 do cars[i] = sim.addCar {} end
local takeover = true
local run = sim.script(version(500, true), { name = "handover.lua" })

local green, minSpeed, stops = nil, math.huge, {}
pitwall.every(0.005, function()
  local all = true
  for _, c in ipairs(cars) do
    if sim.truth(c).targetSpeed <= 0 then all = false end
  end
  if not green and all then
    green = pitwall.now()
    for _, c in ipairs(cars) do stops[c] = sim.truth(c).stopCommands end
    sim.reload(version(600, takeover), green + 3)
    if takeover then sim.reload(version(700, true), green + 6) end
  end
  -- from a second after green until the first car is done, every car drives
  if green and pitwall.now() > green + 1 and pitwall.now() < green + 9 then
    for _, c in ipairs(cars) do
      minSpeed = math.min(minSpeed, sim.truth(c).speed)
      expect.eq(sim.truth(c).stopCommands, stops[c], tostring(c) .. ": no stop from a swap")
    end
  end
end)
expect.truthy(sim.runUntil(function() return run.finished end, 120), "the race finished")
expect.eq(run.version, 3, "two saves took over")
expect.ge(minSpeed, 550, "no speed gap: the cars drove on through both swaps")
local function report(c)
  local f = assert(io.open(out .. c.name))
  local updates, versions, rest = f:read("n", "n", "l")
  f:close()
  os.remove(out .. c.name)
  local from, started = rest:match("^ (%S+) (%d+)$")
  return updates, versions, from, tonumber(started)
end

local raceTime = pitwall.now() - green
for _, c in ipairs(cars) do
  local updates, versions, from, started = report(c)
  expect.eq(versions, 3, tostring(c) .. ": the state came through both swaps")
  expect.eq(from, "counter", "the new driver was told whose state it got")
  expect.eq(started, 0, "a driver that takes over is not started again")
  -- one update every 0.1 s for the whole race, across the versions
  expect.ge(updates, (raceTime - 1) / 0.1 * 0.9, tostring(c) .. ": updates counted across versions")
end

-- Without handover and takeover, the new version's drivers are started as at the green light.
sim.run(1)
takeover = false
run = sim.script(version(500, false), { name = "plain.lua" })
green = nil
expect.truthy(sim.runUntil(function() return run.version == 2 end, 60), "the save took over")
expect.truthy(sim.runUntil(function() return run.finished end, 120), "the race finished")
for _, c in ipairs(cars) do
  local _, versions, from, started = report(c)
  expect.eq(versions, 1, "nothing handed over")
  expect.eq(from, "nil", "no takeover")
  expect.eq(started, 1, "the new driver was started")
end
