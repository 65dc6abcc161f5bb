-- A simulated car tells where it stands across the road from the first moment (docs/simulator.md
-- "Where a car starts"): car.offset is its true offset before any position update, as it is on
-- the grid (−68, −23, +23, +68 mm), not 0 until it first drives.
-- tags: sim
local sim = require "pitwall.sim"

local lanes = { -68, -23, 23, 68 }
for lane, offset in ipairs(lanes) do
  local car = sim.addCar { lane = lane }
  expect.eq(car.piece, nil, "lane " .. lane .. ": no position update yet")
  expect.eq(car.lastPositionTime, nil)
  expect.eq(car.offset, offset, "lane " .. lane .. ": car.offset before it drove")
  expect.eq(car.offset, sim.truth(car).offset, "the simulator's truth")
end
expect.eq(sim.addCar { offset = 12.5 }.offset, 12.5, "an offset given as such")

-- Once it drives, its reports tell (the same offset: it did not move across).
local car = pitwall.cars()[4]
car:setSpeed(500)
expect.truthy(sim.runUntil(function() return car.piece ~= nil end, 5), "a position update")
expect.near(car.offset, 68, 0.5, "as reported")
