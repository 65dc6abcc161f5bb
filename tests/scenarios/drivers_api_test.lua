-- The driver API: loading, the context (ahead, nearby, upcoming, limit, a field that grows),
-- drivers.run's task (start, update every period, finish on stop), a driver whose update
-- raises now and then is reported and still called, and ctx.limit caps the cruiser.
-- tags: drivers
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local drivers = require "pitwall.drivers"

local map = track.fromSim()

expect.fails(function() drivers.load("no-such-driver") end,
  "no driver no-such-driver; the drivers are cruiser, follower, human, lanekeeper, overtaker")
expect.fails(function() drivers.load(42) end, "driver name")
for _, name in ipairs { "cruiser", "lanekeeper", "follower", "overtaker" } do
  local cls = drivers.load(name)
  expect.eq(cls.name, name, "class name")
  expect.eq(type(cls.new().update), "function", name .. " has update")
end
local own = { name = "own", new = function() return { update = function() end } end }
expect.eq(drivers.load(own), own, "a table is taken as is")

-- The context: three cars, one behind, one ahead in another lane.
local a = sim.addCar { lane = 1, piece = 2 }
local b = sim.addCar { lane = 4, piece = 3 }
local c = sim.addCar { lane = 2, piece = 9 }
local field = { a, b }
local ctx = drivers.context(a, map, field, { limit = 600 })
-- The field is kept, not copied: a car added to it later is seen.
field[#field + 1] = { car = c, loc = require("pitwall.localize").follow(c, map) }
expect.eq(ctx.period, 0.1, "default period")
expect.eq(ctx.limit, 600)
expect.eq(ctx:ahead(), nil, "nothing known before the cars have moved")
for _, car in ipairs { a, b, c } do car:setSpeed(300, 1000) end
sim.run(3)
local ahead = ctx:ahead()
expect.truthy(ahead, "a car ahead")
expect.eq(ahead.car, b, "the nearest ahead")
local truthGap = (sim.truth(b).lapDistance - sim.truth(a).lapDistance) % map:lapLength(0)
expect.near(ahead.gap, truthGap, 30, "gap")
expect.near(ahead.time, ahead.gap / 300, 0.2, "time")
expect.near(ahead.lane, 68, 2, "its lane")
local near = ctx:nearby(800)
expect.eq(#near, 2, "two cars within 800 mm (one added to the field later)")
expect.eq(near[1].car, c, "the one behind first")
expect.lt(near[1].gap, 0, "behind is negative")
expect.eq(#ctx:nearby(100), 0, "none within 100 mm")
local up = ctx:upcoming(1000)
expect.eq(up[1].index, ctx.loc.index, "starts with the piece it is on")
expect.ge(#up, 2, "pieces ahead")
expect.eq(up[2].index, map:next(up[1].index), "in driving order")
for _, car in ipairs { b, c } do sim.lift(car) end

-- A driver that raises every seventh update: reported, and called on. (Five failures of a
-- driver's update within 10 s stop its car: driver_errors_test.lua; three here do not.)
local errors = {}
pitwall.onError = function(message, where) errors[#errors + 1] = where .. ": " .. message end
local calls, started, finished = 0, 0, 0
local bad = {
  name = "bad",
  start = function() started = started + 1 end,
  update = function(self, car, ctx)
    calls = calls + 1
    if calls % 7 == 0 then error("boom " .. calls) end
  end,
  finish = function() finished = finished + 1 end,
}
local handle = drivers.run(a, bad, drivers.context(a, map, { a }))
sim.run(2.05)
expect.eq(started, 1, "start once")
expect.near(calls, 21, 1, "update every 0.1 s")
expect.near(#errors, 3, 0, "every raise reported")
expect.truthy(errors[1]:find("boom 7", 1, true), "the message: " .. errors[1])
expect.truthy(errors[1]:find("update of driver bad", 1, true), "where: " .. errors[1])
expect.truthy(handle:stop(), "stop")
expect.falsy(handle:stop(), "stopped once")
expect.eq(finished, 1, "finish on stop")
local n = calls
sim.run(1)
expect.eq(calls, n, "no update after stop")
pitwall.onError = nil

-- ctx.limit caps the cruiser (target 1400) at 600 mm/s.
local maxSpeed = 0
local watch = pitwall.every(0.005, function() maxSpeed = math.max(maxSpeed, sim.truth(a).speed) end)
local h = drivers.run(a, drivers.load("cruiser").new { speed = 1400 }, ctx)
sim.run(15)
expect.le(maxSpeed, 600, "never above the limit")
expect.ge(maxSpeed, 590, "drives up to it")
h:stop()
watch:cancel()
-- Without the limit it goes faster (so the check above can fail).
ctx.limit = nil
h = drivers.run(a, drivers.load("cruiser").new { speed = 1400 }, ctx)
sim.run(5)
expect.gt(sim.truth(a).speed, 700, "faster without the limit")
h:stop()
