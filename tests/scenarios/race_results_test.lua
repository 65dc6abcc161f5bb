-- Qualifying (best lap wins) gives the grid of a race; results as rows, and as CSV and JSON files
-- that parse back.
-- tags: race
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local track = require "pitwall.track"

local speeds = { 600, 800, 1000 }
local cars = {}
for i = 1, 3 do cars[i] = sim.addCar {} end
local map = track.fromSim()
local function drivers(car, i) return race.Steady.new { speed = speeds[i] } end

local base = os.tmpname()
local csv, json = base .. ".csv", base .. ".json"

local q = race.qualifying { laps = 2, map = map, drivers = drivers, results = csv, board = false }
local qrows = q:results()
expect.eq(qrows[1].car, cars[3].name, "pole: the fastest lap")
expect.eq(qrows[3].car, cars[1].name, "last: the slowest")
for k = 2, 3 do expect.ge(qrows[k].bestLap, qrows[k - 1].bestLap, "sorted by best lap") end
expect.eq(q.resultsPath, csv, "written where asked")

-- the CSV parses back
local f = assert(io.open(csv))
local header = f:read("l")
expect.eq(header, table.concat(race.columns, ","), "CSV header")
local parsed = {}
for line in f:lines() do
  local row, k = {}, 0
  for field in (line .. ","):gmatch("([^,]*),") do
    k = k + 1
    row[race.columns[k]] = field
  end
  parsed[#parsed + 1] = row
end
f:close()
expect.eq(#parsed, 3, "a CSV row per car")
for k, row in ipairs(parsed) do
  local want = qrows[k]
  expect.eq(tonumber(row.position), k, "CSV position")
  expect.eq(row.car:gsub('"', ""), want.car, "CSV car")
  expect.eq(tonumber(row.laps), 2, "CSV laps")
  expect.near(tonumber(row.bestLap), want.bestLap, 1e-6, "CSV best lap")
  expect.near(tonumber(row.lastLap), want.lastLap, 1e-6, "CSV last lap")
  expect.near(tonumber(row.totalTime), want.totalTime, 1e-6, "CSV total time")
end

-- the race starts from the qualifying grid
local r = race.laps { laps = 2, map = map, drivers = drivers, grid = q, results = json, board = false }
for k, car in ipairs(q:grid()) do
  expect.eq(r:entry(car).gridSlot, k, "grid slot of " .. tostring(car))
end
local f2 = assert(io.open(json))
local text = f2:read("a")
f2:close()
expect.truthy(text:match("^%s*%[") and text:match("%]%s*$"), "a JSON array")
local n = 0
for _ in text:gmatch('"position"') do n = n + 1 end
expect.eq(n, 3, "an object per car")
for _, c in ipairs(race.columns) do expect.truthy(text:find('"' .. c .. '"', 1, true), "field " .. c) end
for k, row in ipairs(r:results()) do
  expect.truthy(text:find('"car":%s*"' .. row.car .. '"'), "car " .. row.car .. " in the JSON")
end
os.remove(csv); os.remove(json); os.remove(base)

-- Laps after the flag are not results (issue 35): a car that never drives keeps the race
-- waiting (finishTimeout), the finished cars circle at the cool-down speed meanwhile, and the
-- results still give each finisher the race's 2 laps, its best and last of those.
local Parked = { name = "parked", update = function() end }
local waited = race.laps { laps = 2, map = map, board = false, finishTimeout = 20,
  drivers = function(car, i)
    if i == 1 then return setmetatable({}, { __index = Parked }) end
    return race.Steady.new { speed = speeds[i] }
  end }
local finishers = 0
for _, row in ipairs(waited:results()) do
  if row.finished and row.laps > 0 then
    finishers = finishers + 1
    expect.eq(row.laps, 2, row.car .. ": the race's laps, not those circled after the flag")
    local e = waited:entry(pitwall.car(row.car))
    expect.gt(e.timer.count, 2, row.car .. " did circle on after the flag")
    expect.eq(row.lastLap, e.timer.history[2].time, row.car .. ": its last lap is its second")
  end
end
expect.eq(finishers, 2, "two cars finished")
local rows = waited:results()
expect.eq(rows[3].car, cars[1].name, "the car that never drove is last")
expect.eq(rows[3].status, "DNF", "and did not finish")
expect.eq(rows[3].driver, "parked", "its driver named")
expect.eq(rows[1].status, "finished", "the winner finished")
expect.eq(rows[1].driver, "steady", "the winner's driver named")
for k = 2, #rows do
  expect.ge(rows[k].gap or math.huge, rows[k - 1].gap or 0, "gaps down the table")
end
expect.eq(race.winner(waited), string.format("Winner: %s (steady), 2 laps in %s", rows[1].car,
  race.duration(rows[1].totalTime)), "the winner's sentence")
expect.truthy(race.winner(waited):find(" s$"), "a time with its unit")
