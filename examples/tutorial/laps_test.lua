-- Tutorial step 4 (docs/tutorial.md): test laps.lua in virtual time. Run it from the top folder
-- of pitwall:
--
--   build/pitwall test examples/tutorial

local sim = require "pitwall.sim"

local car = sim.addCar {}                              -- one simulated car on the grid
local run = sim.script("examples/tutorial/laps.lua")  -- the script, as `pitwall run` runs it

-- Let the clock run until the script ends the run, or the car is off the track (2 min at most).
sim.runUntil(function() return run.finished or sim.truth(car).delocalized end, 120)

expect.falsy(sim.truth(car).delocalized, "off the track")
expect.truthy(run.finished, "laps.lua finished")
expect.ge(sim.truth(car).laps, 5, "finish lines crossed")
expect.lt(pitwall.now(), 60, "seconds for the scan and 5 laps")
