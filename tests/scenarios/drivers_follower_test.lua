-- A follower (gap 1.0 s, 1000 mm/s) behind a slower car in its lane: checked from the
-- simulator's ground truth every 5 ms tick, it never closes below its gap (centre-line distance
-- over its own speed), settles close to it, speeds up when the car ahead does, and keeps the
-- gap when the car ahead slows down again, stops dead, and drives off.
-- tags: drivers
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local drivers = require "pitwall.drivers"

local map = track.fromSim()
local LAP = map:lapLength(0)
local GAP = 1.0

local lead = sim.addCar { lane = 1, piece = 5 }
local car = sim.addCar { lane = 1, piece = 2 }
local ctx = drivers.context(car, map, { lead, car })
local handle = drivers.run(car, drivers.load("follower").new { gap = GAP, speed = 1000 }, ctx)
lead:setSpeed(500, 1000)
local d0 = (sim.truth(lead).lapDistance - sim.truth(car).lapDistance) % map:lapLength(0)

local minGap, window = math.huge, nil
local function startWindow() window = { sum = 0, n = 0, max = 0 } end
local watch = pitwall.every(0.005, function()
  local a, b = sim.truth(lead), sim.truth(car)
  local d = (a.lapDistance - b.lapDistance) % LAP
  if b.speed > 0 then
    local t = d / b.speed
    minGap = math.min(minGap, t)
    if window then window.sum, window.n, window.max = window.sum + t, window.n + 1, math.max(window.max, t) end
  end
end)

-- It first closes in fast (1000 against 500 mm/s), then follows.
sim.run(20)
startWindow()
sim.run(20)
print(string.format("behind 500 mm/s: time gap mean %.2f s, max %.2f s, min overall %.3f s",
  window.sum / window.n, window.max, minGap))
expect.ge(minGap, GAP, "never below the gap")
expect.le(window.sum / window.n, 1.4 * GAP, "close to the gap (mean time gap)")
expect.le(window.max, 1.6 * GAP, "close to the gap (max time gap)")
local d1 = (sim.truth(lead).lapDistance - sim.truth(car).lapDistance) % LAP
print(string.format("distance at the start %.0f mm, after 40 s %.0f mm", d0, d1))
expect.lt(d1, d0 - 300, "closed in")

-- The car ahead speeds up: so does the follower.
lead:setSpeed(900, 1000)
local fastest = 0
local w2 = pitwall.every(0.005, function() fastest = math.max(fastest, sim.truth(car).speed) end)
sim.run(15)
w2:cancel()
expect.ge(fastest, 880, "speeds up again")
-- …and slows down: the follower keeps its gap.
lead:setSpeed(300, 1500)
sim.run(15)
startWindow()
sim.run(10)
expect.ge(minGap, GAP, "never below the gap when the car ahead slowed down")
expect.le(window.sum / window.n, 1.4 * GAP + 0.3, "close to the gap behind 300 mm/s")
-- …and stops dead (12500 mm/s²): the follower stops behind it, still never below the gap.
lead:stop()
sim.run(5)
expect.ge(minGap, GAP, "never below the gap when the car ahead stopped")
expect.eq(sim.truth(car).speed, 0, "stopped behind it")
local stopped = (sim.truth(lead).lapDistance - sim.truth(car).lapDistance) % LAP
print(string.format("stopped %.0f mm behind (centre to centre)", stopped))
expect.ge(stopped, 95, "not touching")
-- …and drives off again: the follower follows.
lead:setSpeed(600, 1000)
sim.run(10)
expect.ge(sim.truth(car).speed, 300, "drives off again")
expect.ge(minGap, GAP, "never below the gap when driving off")
expect.eq(sim.truth(car).collisions, 0, "no collision")
print(string.format("min time gap over the run %.3f s", minGap))
watch:cancel()
handle:stop()
