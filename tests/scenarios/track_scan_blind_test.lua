-- A scan of a car that sends no position update at all (the transitions sensor model: the
-- worst case, docs/simulator.md) cannot learn the pieces: it ends with a sentence that says why
-- and what to do, soon (30 pieces), not at its timeout, and the car is stopped, not left at the
-- scan speed (docs/racing.md "track.scan").
-- tags: track
local sim = require "pitwall.sim"
local track = require "pitwall.track"
sim.sensor { model = "transitions" }
local car = sim.addCar {}
local started = pitwall.now()
local ok, err = pcall(track.scan, car, { timeout = 600 })
expect.falsy(ok, "the scan failed")
expect.truthy(tostring(err):find("sent no position update on any of them", 1, true), tostring(err))
expect.truthy(tostring(err):find("give the race a map", 1, true), "says what to do")
expect.lt(pitwall.now() - started, 120, "soon, not at the timeout")
sim.run(2)
expect.eq(sim.truth(car).speed, 0, "the car stopped")
