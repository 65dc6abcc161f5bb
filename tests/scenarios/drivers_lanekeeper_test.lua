-- A lane keeper (wrapping a cruiser: the composition pattern) brings its car back to its lane
-- after someone else changed lanes for it and after it was put back on the track elsewhere.
-- tags: drivers
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local drivers = require "pitwall.drivers"

local map = track.fromSim()
local car = sim.addCar { lane = 3, piece = 2 }
local keeper = drivers.load("lanekeeper").new { offset = 23, speed = 900 }
expect.eq(keeper.inner.name, "cruiser", "a cruiser inside by default")
local handle = drivers.run(car, keeper, drivers.context(car, map, { car }))
sim.run(3)
expect.near(sim.truth(car).offset, 23, 2, "in its lane")
expect.ge(sim.truth(car).speed, 800, "the inner cruiser drives")

-- Someone else asks for the outer lane: once the lane keeper sees it, it goes back.
car:changeLane(68, 300)
expect.truthy(sim.runUntil(function() return car.targetOffset ~= 68 end, 1), "answered at once")
expect.truthy(sim.runUntil(function() return math.abs(sim.truth(car).offset - 23) < 2
  and not drivers.changing(car) end, 6), "stays in its lane")

-- Moved while nobody kept the lane (it drifted): once kept again, it goes back.
handle:stop()
car:changeLane(68, 300)
expect.truthy(sim.runUntil(function() return sim.truth(car).offset > 66 and not drivers.changing(car) end, 5),
  "moved to the outer lane")
handle = drivers.run(car, keeper, drivers.context(car, map, { car }))
expect.truthy(sim.runUntil(function() return math.abs(sim.truth(car).offset - 23) < 2
  and not drivers.changing(car) end, 6), "back in its lane after drifting")

-- Put back on the track in another lane (stopped): it drives on and returns to its lane.
sim.place(car, 5, -68)
expect.truthy(sim.runUntil(function() return math.abs(sim.truth(car).offset - 23) < 2
  and not drivers.changing(car) end, 8), "back in its lane after being moved")
expect.ge(sim.truth(car).speed, 500, "driving again")
sim.run(3)
expect.near(sim.truth(car).offset, 23, 2, "stays in its lane")
expect.falsy(sim.truth(car).delocalized, "never delocalized")
handle:stop()
