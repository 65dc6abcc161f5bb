-- For race_reload_test.lua and race_reload_storm_test.lua: the grand prix (examples/grand_prix.lua,
-- unchanged but for 3 laps; 4 cars) run as a script under test while the scenario saves new
-- versions of it; watched from outside by the simulator's ground truth, then checked: one scan
-- lap, one race whose laps are all there and none shorter than the track allows, no stop to any
-- car before it is done racing, car 1's new speed driven after the save that changed it, and
-- results that are those of one race.
local sim = require "pitwall.sim"

local M = {}

local here = debug.getinfo(1, "S").source:sub(2)
local root = here:match("^(.*)/tests/scenarios/") or "."
local f = assert(io.open(root .. "/examples/grand_prix.lua"))
M.v1 = f:read("a"):gsub('tonumber%(os%.getenv%("LAPS"%)%)', "3")
f:close()
local changed
M.v2, changed = M.v1:gsub('{ "cruiser", { speed = 950 } }', '{ "cruiser", { speed = 600 } }')
expect.eq(changed, 1, "the grand prix's first driver is a cruiser at 950 mm/s")
M.v3 = M.v2:gsub("Grand prix, %%d laps", "GP, %%d laps")

--- Runs the grand prix. plan.start(run) schedules saves from the start; plan.green(run, t)
--- those from green on (t: the engine time of green) and returns the time from which car 1
--- drives at 600 mm/s. Returns what was seen.
function M.run(plan)
  local cars = {}
  for i = 1, 4 do cars[i] = sim.addCar {} end
  local o = { cars = cars, results = os.tmpname() .. ".csv", crossings = {}, stopped = {},
    beforeGreen = {}, maxBefore = 0, maxAfter = 0 }
  o.run = sim.script(M.v1, { name = "grand_prix.lua", results = o.results })
  if plan.start then plan.start(o.run) end
  local seen, stops = {}, {}
  for _, c in ipairs(cars) do
    o.crossings[c], seen[c], stops[c] = {}, sim.truth(c).laps, sim.truth(c).stopCommands
  end
  pitwall.every(0.005, function()
    local now = pitwall.now()
    local all = true
    for _, c in ipairs(cars) do
      local t = sim.truth(c)
      if t.laps > seen[c] then
        seen[c] = t.laps
        table.insert(o.crossings[c], now)
      end
      if t.targetSpeed <= 0 then all = false end
      if o.green and not o.stopped[c] and t.stopCommands > stops[c] then o.stopped[c] = now end
      stops[c] = t.stopCommands
    end
    if not o.green and all then -- every car driving: the race is green
      o.green = now
      for _, c in ipairs(cars) do o.beforeGreen[c] = #o.crossings[c] end
      o.changeAt = plan.green(o.run, now)
    end
    if o.green and not o.stopped[cars[1]] and not o.run.finished then
      local v = sim.truth(cars[1]).targetSpeed
      if now < o.changeAt then
        o.maxBefore = math.max(o.maxBefore, v)
      elseif now > o.changeAt + 0.2 then
        o.maxAfter = math.max(o.maxAfter, v)
      end
    end
  end)
  expect.truthy(sim.runUntil(function() return o.run.finished end, 300), "the grand prix finished")
  expect.truthy(o.green, "the race went green")
  expect.falsy(o.run.died, "the script never died")
  return o
end

--- The checks every run must pass.
function M.check(o)
  local cars = o.cars
  -- One scan lap: car 1 crossed the line twice before green (the lap's start and end), the
  -- others never. Or a second lap, when a curve sent no position update on the first (the
  -- real sensor model: car 1 scans on the inner lane, docs/racing.md "On real cars").
  expect.ge(o.beforeGreen[cars[1]], 2, "a scan lap")
  expect.le(o.beforeGreen[cars[1]], 4, "at most two scan laps")
  for k = 2, 4 do expect.eq(o.beforeGreen[cars[k]], 0, "car " .. k .. " waited on the grid") end
  -- The new speed was driven from the save on.
  expect.ge(o.maxBefore, 900, "car 1 at 950 mm/s before the save")
  expect.le(o.maxAfter, 600, "car 1 at most 600 mm/s after the save")
  expect.ge(o.maxAfter, 550, "and it drove that speed")
  -- The results are those of one race.
  local rows = {}
  local rf = assert(io.open(o.results))
  rf:read("l")
  for line in rf:lines() do
    local cells = {}
    for cell in (line .. ","):gmatch("([^,]*),") do cells[#cells + 1] = cell end
    rows[#rows + 1] = { car = cells[2], laps = tonumber(cells[4]), total = tonumber(cells[5]),
      best = tonumber(cells[6]), last = tonumber(cells[7]), finished = cells[8] }
  end
  rf:close()
  os.remove(o.results)
  expect.eq(#rows, 4, "a row per car")
  expect.eq(rows[1].laps, 3, "the winner did 3 laps")
  local byName = {}
  for _, c in ipairs(cars) do byName[c.name] = c end
  for _, row in ipairs(rows) do
    local c = byName[row.car]
    expect.eq(row.finished, "true", row.car .. " finished")
    expect.ge(row.best, 3.0, row.car .. ": no lap shorter than the track allows")
    expect.ge(row.last, 3.0, row.car .. ": last lap")
    -- every crossing after green until its stop is a lap of this race (the first begins lap 1)
    local racing = {}
    for k = o.beforeGreen[c] + 1, #o.crossings[c] do
      local t = o.crossings[c][k]
      if t < (o.stopped[c] or math.huge) then racing[#racing + 1] = t end
    end
    expect.eq(row.laps, #racing - 1, row.car .. ": every lap counted, none twice")
    for k = 2, #racing do
      local lap = racing[k] - racing[k - 1]
      expect.ge(lap, 3.0, row.car .. " lap " .. (k - 1) .. " (ground truth)")
      expect.le(lap, 9.0, row.car .. " lap " .. (k - 1) .. " (ground truth)")
    end
    -- no stop before it was done racing: the first stop after green comes after its last lap
    expect.truthy(o.stopped[c], row.car .. " was stopped at the end")
    expect.gt(o.stopped[c], racing[#racing], row.car .. ": no stop before its finish")
    if row == rows[1] then
      expect.near(row.total, racing[#racing] - o.green, 0.1,
        "the winner's time: from the green light of the one race")
    end
  end
end

return M
