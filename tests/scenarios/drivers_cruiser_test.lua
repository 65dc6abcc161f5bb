-- The cruiser laps the oval's inner lane (−68 mm: 212 mm curve radius) at a 1400 mm/s target
-- without delocalizing — a constant 1400 mm/s there does — and laps faster than a constant speed
-- safe for its curves.
-- tags: drivers
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local drivers = require "pitwall.drivers"

local map = track.fromSim()

-- Seconds per lap over `laps` laps after the first crossing; and the truth seen every tick.
local function lapTime(car, laps)
  local seen = { delocalized = false, maxSpeed = 0 }
  local watch = pitwall.every(0.005, function()
    local t = sim.truth(car)
    if t.delocalized or not t.onTrack then seen.delocalized = true end
    seen.maxSpeed = math.max(seen.maxSpeed, t.speed)
  end)
  local first = sim.truth(car).laps
  expect.truthy(sim.runUntil(function() return sim.truth(car).laps > first end, 20), "first crossing")
  local t0 = pitwall.now()
  expect.truthy(sim.runUntil(function() return sim.truth(car).laps >= first + 1 + laps end, 60),
    "laps driven")
  watch:cancel()
  return (pitwall.now() - t0) / laps, seen
end

-- The control: a constant 1400 mm/s in the inner lane leaves the track in the first curve.
local reckless = sim.addCar { lane = 1, piece = 2 }
reckless:setSpeed(1400, 2000)
expect.truthy(sim.runUntil(function() return sim.truth(reckless).delocalized end, 10),
  "1400 mm/s in the inner lane delocalizes")
sim.lift(reckless)

-- The cruiser.
local car = sim.addCar { lane = 1, piece = 2 }
local cruiser = drivers.load("cruiser")
expect.eq(cruiser.name, "cruiser")
local handle = drivers.run(car, cruiser.new { speed = 1400 }, drivers.context(car, map, { car }))
local cruiseLap, seen = lapTime(car, 5)
expect.falsy(seen.delocalized, "the cruiser never delocalized")
expect.ge(seen.maxSpeed, 1390, "reaches its target on the straights")
expect.eq(sim.truth(car).collisions, 0, "collisions")
handle:stop()
car:stop()
sim.run(2)
sim.lift(car)

-- A constant speed safe for the same curves at the same lateral acceleration (7000 mm/s²).
local safe = math.floor(math.sqrt(7000 * (280 - 68)))
local steady = sim.addCar { lane = 1, piece = 2 }
steady:setSpeed(safe, 2000)
local steadyLap, seen2 = lapTime(steady, 5)
expect.falsy(seen2.delocalized, "constant safe speed")
print(string.format("inner lane: cruiser %.3f s/lap, constant %d mm/s %.3f s/lap", cruiseLap, safe,
  steadyLap))
expect.lt(cruiseLap, steadyLap * 0.97, "the cruiser laps at least 3 % faster")
