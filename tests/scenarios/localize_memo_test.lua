-- A tracker asked twice where its car will be at the same moment keeps its first answer only
-- while nothing it reckons with changed (pitwall/localize.lua, Tracker:locate): an event of the
-- car, or — for a car whose speed update says no acceleration (firmware 0x266e) — a new
-- commanded speed gives a new answer, the same as a second tracker that was never asked.
-- tags: track
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local localize = require "pitwall.localize"

local car = sim.addCar { firmware = 0x266e, lane = 1, piece = 2, distance = 100 }
-- two maps of the same track: two trackers of the one car, fed the same events
local a = localize.follow(car, track.fromSim())
local b = localize.follow(car, track.fromSim())
expect.truthy(a ~= b, "a tracker per map")
car:setSpeed(800, 25000)
expect.truthy(sim.runUntil(function() return a.anchored and b.anchored end, 5), "anchored")
sim.run(0.3)

-- Asked again after an event: the event's answer, not the one kept.
local t = pitwall.now() + 0.4
local first = a:locate(t)
expect.eq(a:locate(t), first, "the same moment asked again: the same answer")
local since = a.time
expect.truthy(sim.runUntil(function() return a.time > since end, 2), "an event came")
expect.eq(a:locate(t), b:locate(t), "after an event: what a tracker never asked says")
expect.truthy(a:locate(t) ~= first, "after an event: a new answer (the reckoning was corrected)")

-- A slower speed commanded, no speed update yet (the older firmware's says no acceleration: the
-- car is taken to brake hard): asked again at once, the nearer place.
t = pitwall.now() + 0.3
local before = a:locate(t)
expect.eq(b:locate(t), before, "both trackers agree")
car:setSpeed(300, 1000)
expect.lt(a:locate(t), before, "told to slow down: reckoned nearer")
expect.eq(a:locate(t), b:locate(t), "told to slow down: what the other tracker says")
