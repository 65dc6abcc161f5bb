-- The race director, fixed laps: finish order and laps vs the simulator's ground truth; every car
-- stopped at the end; results rows; positions and gaps (race_truth.lua).
-- tags: race
local sim = require "pitwall.sim"
-- As real cars report (docs/simulator.md "Sensor model"): finish order and laps hold.
sim.sensor { model = "real" }

local r = require "race_truth"(5)
local cars, finishes = r.cars, r.finishes
local rows = r.race:results()
expect.eq(#rows, 4, "a row per car")
expect.eq(rows[1].laps, 5, "the winner drove 5 laps")
expect.eq(rows[1].car, cars[1].name, "the fastest car wins")
for k, row in ipairs(rows) do
  expect.eq(row.position, k, "positions")
  expect.gt(row.totalTime, 0, "total time")
  expect.le(row.bestLap, row.lastLap + 1e-9, "best ≤ last")
  expect.falsy(row.falseStart, "no false start")
  if k > 1 then
    -- classified by laps, then by the time they took
    expect.le(row.laps, rows[k - 1].laps, "laps fall")
    if row.laps == rows[k - 1].laps then
      expect.ge(row.totalTime, rows[k - 1].totalTime, "total times rise")
    end
  end
end
expect.ge(r.laps, 5 + 4 + 3, "onLap events")
expect.ge(r.atLeaderFinish.rows[4].lapsBehind, 2, "the slowest car lapped twice")
expect.eq(finishes[1], cars[1], "the winner finished first")
expect.ge(r.changes, 0, "onPositionChange")
