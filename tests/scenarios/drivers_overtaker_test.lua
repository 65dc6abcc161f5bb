-- An overtaker (1000 mm/s, lanes −68 / +68) passes a car at 500 mm/s on the oval within N = 3 of
-- its own laps, without a collision, and returns to its lane. With a third car alongside the
-- slow one in the passing lane it does not change lanes (it follows) until the way is clear; in
-- traffic coming faster in the passing lane it never changes into a car.
-- tags: drivers
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local drivers = require "pitwall.drivers"

local map = track.fromSim()
local LAP = map:lapLength(0)
local N = 3

-- Distance driven along the centre line, unwrapped (the truth's lap distance wraps).
local function odometer(car)
  local o = { total = 0, last = sim.truth(car).lapDistance }
  o.timer = pitwall.every(0.005, function()
    local d = sim.truth(car).lapDistance
    o.total = o.total + (d - o.last + LAP / 2) % LAP - LAP / 2
    o.last = d
  end)
  return o
end

local slow = sim.addCar { lane = 1, piece = 4 }
local car = sim.addCar { lane = 1, piece = 2 }
local slowOdo, carOdo = odometer(slow), odometer(car)
local start = (sim.truth(slow).lapDistance - sim.truth(car).lapDistance) % LAP -- slow car ahead
local ctx = drivers.context(car, map, { slow, car })
local driver = drivers.load("overtaker").new { speed = 1000, lanes = { -68, 68 } }
local maxOffset = -100
local watchLane = pitwall.every(0.005, function() maxOffset = math.max(maxOffset, sim.truth(car).offset) end)
local handle = drivers.run(car, driver, ctx)
slow:setSpeed(500, 1000)

local function ahead() return carOdo.total - slowOdo.total - start end -- > 0: car passed slow
expect.truthy(sim.runUntil(function() return ahead() > 200 end, N * LAP / 1000 * 1.6),
  "passed within " .. N .. " laps")
expect.le(carOdo.total, N * LAP, "within N laps")
print(string.format("passed after %.0f mm (%.2f laps) at %.1f s", carOdo.total, carOdo.total / LAP, pitwall.now()))
expect.ge(maxOffset, 60, "passed in the other lane")
expect.truthy(sim.runUntil(function() return math.abs(sim.truth(car).offset + 68) < 2
  and not drivers.changing(car) end, 5), "back in its lane")
expect.ge(ahead(), driver.margin, "returned only ahead of the passed car")
expect.eq(driver.passes, 1, "one pass")
sim.run(5)
expect.eq(sim.truth(car).collisions, 0, "no collision (overtaker)")
expect.eq(sim.truth(slow).collisions, 0, "no collision (slow car)")
expect.falsy(sim.truth(car).delocalized, "never delocalized")
handle:stop()
watchLane:cancel()
car:stop(); slow:stop()
sim.run(2)
for _, c in ipairs { car, slow } do sim.lift(c) end

-- Blocked: a car in the passing lane beside the slow one. The overtaker must not change lanes.
local slow2 = sim.addCar { lane = 1, piece = 6 }
-- In the outer lane at 620 mm/s it laps in the inner lane's 500 mm/s lap time (4427 vs 3572 mm),
-- so it stays beside the slow car (ahead on the straights, behind in the curves).
local block = sim.addCar { lane = 4, piece = 6, distance = 200 }
local car2 = sim.addCar { lane = 1, piece = 3 }
slow2:setSpeed(500, 1000); block:setSpeed(620, 1000)
local d2 = drivers.load("overtaker").new { speed = 1000 }
maxOffset = -100
watchLane = pitwall.every(0.005, function() maxOffset = math.max(maxOffset, sim.truth(car2).offset) end)
local h2 = drivers.run(car2, d2, drivers.context(car2, map, { slow2, block, car2 }))
sim.run(20)
expect.le(maxOffset, -60, "stayed in its lane while the passing lane was taken")
expect.eq(d2.passes, 0, "no pass while blocked")
-- The blocking car leaves: it passes.
sim.lift(block)
expect.truthy(sim.runUntil(function() return d2.passes == 1 end, 20), "passes once clear")
sim.run(5)
for _, c in ipairs { car2, slow2 } do
  expect.eq(sim.truth(c).collisions, 0, "no collision while blocked " .. tostring(c))
end
h2:stop()
for _, c in ipairs { car2, slow2 } do c:stop() end
sim.run(2)
for _, c in ipairs { car2, slow2 } do sim.lift(c) end

-- Traffic in the passing lane: a cruiser at 1400 mm/s in the outer lane keeps coming from behind
-- and lapping everyone (it brakes for nobody). The overtaker passes when it has the time to, and
-- never changes into it or in front of it.
local slow3 = sim.addCar { lane = 1, piece = 6 }
local car3 = sim.addCar { lane = 1, piece = 4 }
local fast = { sim.addCar { lane = 4, piece = 2 } }
local all = { slow3, car3, fast[1] }
slow3:setSpeed(500, 1000)
local handles = {}
for _, f in ipairs(fast) do
  handles[#handles + 1] = drivers.run(f, drivers.load("cruiser").new { speed = 1400 },
    drivers.context(f, map, all))
end
local d3 = drivers.load("overtaker").new { speed = 1000 }
handles[#handles + 1] = drivers.run(car3, d3, drivers.context(car3, map, all))
sim.run(60)
print(string.format("in traffic: %d passes in 60 s", d3.passes))
expect.ge(d3.passes, 3, "passes in traffic")
for _, c in ipairs(all) do
  expect.eq(sim.truth(c).collisions, 0, "no collision in traffic " .. tostring(c))
  expect.falsy(sim.truth(c).delocalized, "on the track " .. tostring(c))
end
for _, h in ipairs(handles) do h:stop() end
