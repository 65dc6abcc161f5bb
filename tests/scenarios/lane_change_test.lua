-- A lane change reaches the target offset: the car reports it (onOffset, position updates) and
-- the simulator's ground truth agrees.
-- tags: sim
local sim = require "pitwall.sim"

local car = sim.addCar { lane = 1 }
local offsets = {}
car.onOffset = function(car, ev) offsets[#offsets + 1] = ev.offset end

car:setSpeed(600, 2000)
sim.run(1)
car:changeLane(68, 300, 3000)
expect.truthy(car.laneChanging, "lane change under way")
expect.eq(car.targetOffset, 68)

expect.truthy(sim.runUntil(function() return #offsets > 0 end, 5), "an offset update within 5 s")
expect.near(offsets[1], 68, 1, "reported offset")
expect.near(sim.truth(car).offset, 68, 1, "true offset")
expect.falsy(car.laneChanging, "lane change done")

-- Position updates carry the new offset too.
local seen
car.onPosition = function(car, ev) seen = ev.offset end
sim.runUntil(function() return seen ~= nil end, 2)
expect.near(seen, 68, 1, "offset in position updates")
expect.near(car.offset, 68, 1, "car.offset")

-- Out of range is refused with the range named, and nothing is sent: beyond ±70 mm the car
-- leaves the road (seed 000 §4.3.4.4).
local before = car.frames
expect.fails(function() car:changeLane(150) end,
  "offset 150 mm is out of range -70..70 mm (beyond it the car leaves the road)")
expect.fails(function() car:changeLane(-70.5) end, "offset -70.5 mm is out of range -70..70 mm")
expect.fails(function() car:setOffset(90) end, "offset 90 mm is out of range -70..70 mm")
expect.eq(car.frames, before, "frames after a refused command")
