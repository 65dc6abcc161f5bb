-- A script that pauses between two sessions (qualifying, 3 s, then the race) is saved mid-race:
-- the new version runs the finished qualifying (it returns at once) and the pause again, but the
-- race does not wait for it — it goes on at once, timed and counted, and the script's call takes
-- it up 3 s later. Every line crossing is a lap of the one race, and the winner's time is the
-- same as without the save.
-- tags: race reload
local sim = require "pitwall.sim"

local cars = {}
for i = 1, 3 do cars[i] = sim.addCar {} end
local results = os.tmpname() .. ".csv"
local source = string.format([[
local race = require "pitwall.race"
local function steady(car, i) return race.Steady.new { speed = 700 + 100 * i } end
local q = race.qualifying { laps = 2, drivers = steady, board = false, results = false }
pitwall.sleep(3)
race.laps { laps = 4, grid = q, drivers = steady, board = false, results = %q }
pitwall.stop()
]], results)

local k34
for k, p in ipairs(sim.track().pieces) do if p.id == 34 then k34 = k end end
local lanes = { -68, -23, 23 }

-- the race's results, and every car's line crossings, with the save at `at` (nil: none); each
-- run from the same start: the cars put on the grid piece, in lanes of their own
local function race(at)
  for i, c in ipairs(cars) do
    sim.lift(c)
    sim.run(0.1)
    sim.place(c, k34, lanes[i])
  end
  sim.run(1)
  local start = {}
  for _, c in ipairs(cars) do start[c] = sim.truth(c).laps end
  local begun = pitwall.now()
  local run = sim.script(source)
  if at then sim.reload(source, begun + at) end
  expect.truthy(sim.runUntil(function() return run.finished end, 300), "finished")
  expect.eq(run.version, at and 2 or 1)
  local rows = {}
  local f = assert(io.open(results))
  f:read("l")
  for line in f:lines() do
    local name, laps, total = line:match("^%d+,([^,]+),%d+,(%d+),([^,]*),")
    rows[name] = { laps = tonumber(laps), total = tonumber(total) }
  end
  f:close()
  os.remove(results)
  local crossed = {}
  for _, c in ipairs(cars) do crossed[c.name] = sim.truth(c).laps - start[c] end
  sim.run(1)
  return rows, crossed
end

local plain = race(nil)
local saved, crossed = race(40) -- mid-race (green at about 30 s)
for name, row in pairs(saved) do
  expect.eq(row.laps, plain[name].laps, name .. ": the same laps as without the save")
  expect.near(row.total, plain[name].total, 0.05, name .. ": the same time")
end
for _, c in ipairs(cars) do expect.truthy(saved[c.name], c.name .. " in the results") end
expect.truthy(crossed, "crossings recorded")
