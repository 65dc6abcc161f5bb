-- A race against the simulator's ground truth, for the scenarios that run it under one sensor
-- model or another (race_laps_test.lua: the real model; race_transitions_test.lua: transitions
-- only). Four cars of Steady drivers at 900, 800, 700 and 600 mm/s race `laps` laps; checked:
-- the order at the leader's finish as the truth has it, laps behind, the gap to the leader at the
-- line, every car's laps as the truth counts them, every car finished and stopped. Returns what
-- the caller checks beside: the race, the cars, onLap and onPositionChange counts, the finishes.
-- `specs` (optional): sim.addCar's table for each car; `before(cars)`, called before the race.
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local track = require "pitwall.track"

return function(laps, specs, before)
  local speeds = { 900, 800, 700, 600 }
  local cars = {}
  for i = 1, 4 do cars[i] = sim.addCar(specs and specs[i] or {}) end
  if before then before(cars) end

  local function truthOrder()
    local list = {}
    for _, c in ipairs(cars) do
      local t = sim.truth(c)
      list[#list + 1] = { car = c, p = t.laps + t.lapDistance / 4000 }
    end
    table.sort(list, function(a, b) return a.p > b.p end)
    return list
  end

  local out = { cars = cars, finishes = {}, changes = 0, laps = 0 }
  local crossings, gapChecked, atLeaderFinish, truthLaps = {}, nil, nil, {}
  out.race = race.laps {
    laps = laps, map = track.fromSim(), results = false, board = false,
    drivers = function(car, i) return race.Steady.new { speed = speeds[i] } end,
    onFinish = function(car, position, session)
      out.finishes[#out.finishes + 1] = car
      truthLaps[car] = sim.truth(car).laps
      if position == 1 then
        atLeaderFinish = { truth = truthOrder(), grid = session:grid(), rows = session:results() }
      end
    end,
    onPositionChange = function() out.changes = out.changes + 1 end,
    onLap = function(car, lap, session)
      out.laps = out.laps + 1
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

  expect.eq(#out.finishes, 4, "every car finished")
  expect.truthy(atLeaderFinish, "the leader finished")
  for k, x in ipairs(atLeaderFinish.truth) do
    local behind = math.floor(atLeaderFinish.truth[1].p - x.p)
    expect.eq(atLeaderFinish.rows[k].lapsBehind, behind, tostring(x.car) .. " laps behind, vs truth")
    expect.eq(atLeaderFinish.grid[k], x.car, "position " .. k .. " at the leader's finish vs truth")
  end
  expect.truthy(gapChecked, "gap checked")
  expect.near(gapChecked[1], gapChecked[2], 0.03, "gap to the leader at the line")
  expect.eq(gapChecked[3], 0, "not a lap behind")
  for _, row in ipairs(out.race:results()) do
    expect.truthy(row.finished, row.car .. " finished")
    -- the simulator counts the crossing from the grid too
    expect.eq(row.laps, truthLaps[pitwall.car(row.car)] - 1, row.car .. " laps vs truth")
  end
  for _, c in ipairs(cars) do expect.eq(sim.truth(c).speed, 0, tostring(c) .. " stopped") end
  sim.run(2)
  for _, c in ipairs(cars) do expect.eq(sim.truth(c).speed, 0, tostring(c) .. " still stopped") end
  out.atLeaderFinish = atLeaderFinish
  return out
end
