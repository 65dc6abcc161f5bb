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

-- A car that stands takes no lane change (real cars steer only while they roll,
-- anki-overdrive.md): it is refused with the car, its speed and what to do, and nothing is sent,
-- so the car does not swerve when it starts later.
local parked = sim.addCar { lane = 1 }
local label = string.format("car %d (%s)", parked.number, parked.name)
local sent = parked.frames
expect.fails(function() parked:changeLane(68) end,
  label .. " stands (speed 0 mm/s); a lane change needs a moving car (real cars steer only while "
  .. "they roll); setSpeed first (300 mm/s or more changes lanes reliably), then changeLane")
expect.eq(parked.frames, sent, "nothing sent to the standing car")
expect.falsy(parked.laneChanging)
parked:setSpeed(500)
expect.truthy(sim.runUntil(function() return parked.speed > 0 end, 2), "it drives")
sim.run(3)
expect.near(sim.truth(parked).offset, -68, 1, "the refused lane change was not carried out later")

-- Told to drive, it may change lanes at once (before it reports any speed) …
parked:stop()
expect.truthy(sim.runUntil(function() return sim.truth(parked).speed == 0 end, 2), "stopped")
parked:setSpeed(500)
parked:changeLane(-23)
expect.truthy(sim.runUntil(function() return not parked.laneChanging end, 5), "changed lanes")
expect.near(sim.truth(parked).offset, -23, 1, "in the new lane")
-- … told to stop, it still steers while it rolls (a driver braking behind a slower car), and
-- takes none once it stands.
parked:stop()
expect.gt(parked.speed, 0, "still rolling just after stop()")
parked:changeLane(-68)
expect.truthy(sim.runUntil(function() return sim.truth(parked).speed == 0 end, 3), "it stands")
sim.run(1)  -- a car that stops falls silent: its last report, older than 0.5 s, is stale
expect.fails(function() parked:changeLane(23) end, label .. " stands (")
