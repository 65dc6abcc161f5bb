-- The grand prix (examples/grand_prix.lua, unchanged but for 3 laps; 4 cars) survives saves of
-- itself: during the scan lap, on the way to the grid, during the lights, a changed driver speed
-- mid-race, a broken version, and one more. The scenario watches from outside, by the
-- simulator's ground truth: one scan lap, one race whose laps are all there and none shorter
-- than the track allows, no stop to any car before it is done racing, the new speed driven
-- after the save, and results that are those of one race.
local sim = require "pitwall.sim"

local here = debug.getinfo(1, "S").source:sub(2)
local root = here:match("^(.*)/tests/scenarios/") or "."
local f = assert(io.open(root .. "/examples/grand_prix.lua"))
local v1 = f:read("a"):gsub('tonumber%(os%.getenv%("LAPS"%)%)', "3")
f:close()
local v2, changed = v1:gsub('{ "cruiser", { speed = 950 } }', '{ "cruiser", { speed = 600 } }')
expect.eq(changed, 1, "the grand prix's first driver is a cruiser at 950 mm/s")
local v3 = v2:gsub("Grand prix, %%d laps", "GP, %%d laps")

local cars = {}
for i = 1, 4 do cars[i] = sim.addCar {} end
local results = os.tmpname() .. ".csv"
local run = sim.script(v1, { name = "grand_prix.lua", results = results })
sim.reload(v1, 5)  -- the scan lap (it begins at once and takes over 10 s)
sim.reload(v1, 16) -- on the way to the grid
sim.reload(v1, 20) -- the lights

local crossings, seen, stopped, stops = {}, {}, {}, {}
for _, c in ipairs(cars) do
  crossings[c], seen[c] = {}, sim.truth(c).laps
  stops[c] = sim.truth(c).stopCommands
end
local green, changeAt, beforeGreen = nil, nil, {}
local maxBefore, maxAfter = 0, 0
pitwall.every(0.005, function()
  local now = pitwall.now()
  local all = true
  for _, c in ipairs(cars) do
    local t = sim.truth(c)
    if t.laps > seen[c] then
      seen[c] = t.laps
      table.insert(crossings[c], now)
    end
    if t.targetSpeed <= 0 then all = false end
    if green and not stopped[c] and t.stopCommands > stops[c] then stopped[c] = now end
    stops[c] = t.stopCommands
  end
  if not green and all then
    -- every car driving: the race is green. Now the saves mid-race.
    green = now
    for _, c in ipairs(cars) do beforeGreen[c] = #crossings[c] end
    changeAt = now + 4
    sim.reload(v2, changeAt)  -- car 1's cruiser: 950 → 600 mm/s
    sim.reload("local broken = ", now + 6)
    sim.reload(v3, now + 8)
  end
  if green and not stopped[cars[1]] and not run.finished then
    local v = sim.truth(cars[1]).targetSpeed
    if now < changeAt then
      maxBefore = math.max(maxBefore, v)
    elseif now > changeAt + 0.2 then
      maxAfter = math.max(maxAfter, v)
    end
  end
end)

expect.truthy(sim.runUntil(function() return run.finished end, 200), "the grand prix finished")
expect.truthy(green, "the race went green")
expect.eq(run.version, 6, "versions: the first, three before green, two mid-race")
expect.eq(run.refused, 1, "the broken version was refused")
expect.truthy(run.refusal:find("grand_prix.lua:1:", 1, true), "refused with file and line")
expect.falsy(run.died, "the script never died")

-- One scan lap: car 1 crossed the line twice before green (the lap's start and end), the
-- others never.
expect.eq(beforeGreen[cars[1]], 2, "one scan lap")
for k = 2, 4 do expect.eq(beforeGreen[cars[k]], 0, "car " .. k .. " waited on the grid") end

-- The new speed was driven from the save on.
expect.ge(maxBefore, 900, "car 1 at 950 mm/s before the save")
expect.le(maxAfter, 600, "car 1 at most 600 mm/s after the save")
expect.ge(maxAfter, 550, "and it drove that speed")

-- The results are those of one race.
local rows = {}
local rf = assert(io.open(results))
rf:read("l")
for line in rf:lines() do
  local cells = {}
  for cell in (line .. ","):gmatch("([^,]*),") do cells[#cells + 1] = cell end
  rows[#rows + 1] = { car = cells[2], laps = tonumber(cells[4]), total = tonumber(cells[5]),
    best = tonumber(cells[6]), last = tonumber(cells[7]), finished = cells[8] }
end
rf:close()
os.remove(results)
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
  for k = beforeGreen[c] + 1, #crossings[c] do
    if crossings[c][k] < (stopped[c] or math.huge) then racing[#racing + 1] = crossings[c][k] end
  end
  expect.eq(row.laps, #racing - 1, row.car .. ": every lap counted, none twice")
  for k = 2, #racing do
    local lap = racing[k] - racing[k - 1]
    expect.ge(lap, 3.0, row.car .. " lap " .. (k - 1) .. " (ground truth)")
    expect.le(lap, 9.0, row.car .. " lap " .. (k - 1) .. " (ground truth)")
  end
  -- no stop before it was done racing: the first stop after green comes after its last lap
  expect.truthy(stopped[c], row.car .. " was stopped at the end")
  expect.gt(stopped[c], racing[#racing], row.car .. ": no stop before its finish")
  if row == rows[1] then
    expect.near(row.total, racing[#racing] - green, 0.1,
      "the winner's time: from the green light of the one race")
  end
end
