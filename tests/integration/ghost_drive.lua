-- The ghost of the best lap of GHOST_RECORD races car 1 (tests/integration/ghost_test.sh): the
-- ghost is told to go with the car, and the run lasts 30 s.
local sim = require "pitwall.sim"
local ghost = sim.addGhost { record = "even.jsonl", lap = "best" }
print("ghost:", ghost.name, ghost.ghost, pitwall.cars()[1].ghost)
local car = pitwall.cars()[1]
car:setSpeed(600, 20000)
ghost:setSpeed(600, 20000)            -- any speed above 0: it drives its lap
ghost:changeLane(68)                  -- taken by no ghost
pitwall.spawn(function()
  pitwall.sleep(30)
  print("ghost offset:", sim.truth(ghost).offset, "collisions:", sim.truth(ghost).collisions)
  pitwall.stop()
end)
