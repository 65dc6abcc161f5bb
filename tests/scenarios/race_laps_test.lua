-- The race director, fixed laps: finish order and laps vs the simulator's ground truth; every car
-- stopped at the end; results rows; positions and gaps.
-- tags: race
local sim = require "pitwall.sim"
-- As real cars report (docs/simulator.md "Sensor model"): finish order and laps hold.
sim.sensor { model = "real" }
local race = require "pitwall.race"
local track = require "pitwall.track"

local speeds = { 900, 800, 700, 600 }
local cars = {}
for i = 1, 4 do cars[i] = sim.addCar {} end

local function truthOrder()
  local list = {}
  for _, c in ipairs(cars) do
    local t = sim.truth(c)
    list[#list + 1] = { car = c, p = t.laps + t.lapDistance / 4000 }
  end
  table.sort(list, function(a, b) return a.p > b.p end)
  return list
end

local crossings, gapChecked = {}, nil
local atLeaderFinish, finishes, truthLaps, changes, laps = nil, {}, {}, 0, 0
local r = race.laps {
  laps = 5, map = track.fromSim(), results = false, board = false,
  drivers = function(car, i) return race.Steady.new { speed = speeds[i] } end,
  onFinish = function(car, position, session)
    finishes[#finishes + 1] = car
    truthLaps[car] = sim.truth(car).laps
    if position == 1 then
      atLeaderFinish = { truth = truthOrder(), grid = session:grid(), rows = session:results() }
    end
  end,
  onPositionChange = function() changes = changes + 1 end,
  onLap = function(car, lap, session)
    laps = laps + 1
    crossings[car] = crossings[car] or {}
    crossings[car][lap.number] = lap.finish
    if car == cars[2] and lap.number == 3 then
      -- just after the line: its gap to the leader is the time between their crossings
      pitwall.after(0.15, function()
        local row = session:results()[session:entry(car).position]
        gapChecked = { row.gap, lap.finish - crossings[cars[1]][3], row.lapsBehind }
      end)
    end
  end,
}

expect.truthy(atLeaderFinish, "the leader finished")
expect.truthy(gapChecked, "gap checked")
for k, x in ipairs(atLeaderFinish.truth) do
  local behind = math.floor(atLeaderFinish.truth[1].p - x.p)
  expect.eq(atLeaderFinish.rows[k].lapsBehind, behind, tostring(x.car) .. " laps behind, vs truth")
end
expect.ge(atLeaderFinish.rows[4].lapsBehind, 2, "the slowest car lapped twice")
expect.near(gapChecked[1], gapChecked[2], 0.03, "gap to the leader at the line")
expect.eq(gapChecked[3], 0, "not a lap behind")
for k, x in ipairs(atLeaderFinish.truth) do
  expect.eq(atLeaderFinish.grid[k], x.car, "position " .. k .. " at the leader's finish vs truth")
end
local rows = r:results()
expect.eq(#rows, 4, "a row per car")
expect.eq(rows[1].laps, 5, "the winner drove 5 laps")
expect.eq(rows[1].car, cars[1].name, "the fastest car wins")
for k, row in ipairs(rows) do
  expect.eq(row.position, k, "positions")
  expect.truthy(row.finished, row.car .. " finished")
  -- the simulator counts the crossing from the grid too
  expect.eq(row.laps, truthLaps[pitwall.car(row.car)] - 1, row.car .. " laps vs truth")
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
expect.ge(laps, 5 + 4 + 3, "onLap events")
expect.eq(#finishes, 4, "every car finished")
expect.eq(finishes[1], cars[1], "the winner finished first")
expect.ge(changes, 0, "onPositionChange")
-- every car stopped
for _, c in ipairs(cars) do expect.eq(sim.truth(c).speed, 0, tostring(c) .. " stopped") end
sim.run(2)
for _, c in ipairs(cars) do expect.eq(sim.truth(c).speed, 0, tostring(c) .. " still stopped") end
