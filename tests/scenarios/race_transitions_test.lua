-- The worst case (docs/simulator.md "Sensor model"): not one position update, only the
-- transition at each piece boundary. The race director's laps, the order at the leader's finish,
-- laps behind, the gap at the line and the stop hold as the simulator's ground truth says
-- (race_truth.lua); tests/integration/transitions_seeds_test.sh runs it over more seeds.
-- tags: race
local sim = require "pitwall.sim"
sim.sensor { model = "transitions" }

local r = require "race_truth"(4)
for _, c in ipairs(r.cars) do
  expect.eq(c.lastPositionTime, nil, tostring(c) .. " never sent a position update")
end
