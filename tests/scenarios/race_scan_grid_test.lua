-- Five cars and a scan lap (found by the link soak, issue 36): a grid has 4 lanes, so the fifth
-- car stands in a second row behind the line and the scan car ran into it, the scan failing
-- 120 s later with "no complete lap". Now the race refuses at once with a sentence; without a
-- scan (the simulator's layout is the map; on real cars --track's) five cars race.
-- tags: race sim
local sim = require "pitwall.sim"
local race = require "pitwall.race"

for _ = 1, 5 do sim.addCar {} end
local began = pitwall.now()
expect.fails(function() race.laps { laps = 1, scan = true, board = false } end,
  "5 cars and a scan lap: a grid has 4 lanes", "a scan lap with 5 cars is refused")
expect.fails(function() race.laps { laps = 1, scan = true, board = false } end,
  "give the layout the cars are on (--track LAYOUT", "the sentence says what to do on real cars")
expect.near(pitwall.now() - began, 0, 0.5, "at once, not after the scan's timeout")
for _, car in ipairs(pitwall.cars()) do
  expect.eq(car.targetSpeed or 0, 0, car.name .. " was not set moving")
end
local r = race.laps { laps = 1, board = false }
for _, row in ipairs(r:results()) do
  expect.eq(row.status, "finished", row.car .. " finished a race without a scan lap")
end
