-- Too fast in a curve the car leaves the track: it reports delocalized, stops, and the
-- simulator agrees. A slower car in the outer lane keeps going.
-- tags: track sim
local sim = require "pitwall.sim"

local fast = sim.addCar { lane = 1, name = "fast" }       -- inner lane of the left curves
local steady = sim.addCar { lane = 4, name = "steady" }    -- outer lane
local delocalizedAt
fast.onDelocalized = function(car, ev) delocalizedAt = ev.time end
steady.onDelocalized = function() error("the steady car must not delocalize") end

fast:setSpeed(1500, 25000)   -- 1500²/212 mm/s² ≈ 10600 mm/s² > 9000 in the inner lane
steady:setSpeed(900, 25000)  -- 900²/348 ≈ 2300 mm/s²

expect.truthy(sim.runUntil(function() return delocalizedAt ~= nil end, 10), "delocalized within 10 s")
expect.truthy(fast.delocalized, "car.delocalized")
local t = sim.truth(fast)
expect.truthy(t.delocalized, "truth: delocalized")
expect.eq(sim.track().pieces[t.pieceIndex].type, "curve", "where it left the track")

sim.run(2)
expect.eq(sim.truth(fast).speed, 0, "the delocalized car has stopped")
expect.gt(sim.truth(steady).speed, 800, "the other car drives on")

-- Put back on the track, it drives again.
sim.place(fast, 3, -23)
fast:setSpeed(500)
local positions = 0
fast.onPosition = function() positions = positions + 1 end
expect.truthy(sim.runUntil(function() return positions >= 3 end, 5), "reports again after place")
expect.falsy(fast.delocalized)
