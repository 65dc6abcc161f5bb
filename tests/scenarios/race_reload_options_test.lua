-- What a save may change in a race under way: more laps make the race longer; fewer than the
-- leader has done end it at the leader's next crossing; another kind of session (a timed race
-- instead of laps) is refused with a warning and the race goes on as it was.
-- tags: race reload
local sim = require "pitwall.sim"

local cars = {}
for i = 1, 3 do cars[i] = sim.addCar {} end

local function source(call, results) -- call: "laps { laps = 2 }"
  local kind, options = call:match("^(%w+) { (.*) }$")
  return string.format([[
local race = require "pitwall.race"
race.%s { %s, results = %q, board = false,
  drivers = function(car, i) return race.Steady.new { speed = 700 + 100 * i } end }
pitwall.stop()
]], kind, options, results)
end

-- runs `first`, saves `second` once the leader crossed the line `after` times; the result rows
local function run(first, second, after)
  local results = os.tmpname() .. ".csv"
  local handle = sim.script(source(first, results))
  local base = {}
  for _, c in ipairs(cars) do base[c] = sim.truth(c).laps end
  local saved = false
  local watch = pitwall.every(0.005, function()
    if saved then return end
    for _, c in ipairs(cars) do
      if sim.truth(c).laps - base[c] >= after then
        saved = true
        sim.reload(source(second, results))
      end
    end
  end)
  expect.truthy(sim.runUntil(function() return handle.finished end, 300), first .. " finished")
  watch:cancel()
  expect.truthy(saved, "saved mid-race")
  expect.eq(handle.version, 2, "the save took over")
  local rows = {}
  local f = assert(io.open(results))
  f:read("l")
  for line in f:lines() do
    local cells = {}
    for cell in (line .. ","):gmatch("([^,]*),") do cells[#cells + 1] = cell end
    rows[#rows + 1] = { laps = tonumber(cells[4]), finished = cells[8] }
  end
  f:close()
  os.remove(results)
  sim.run(1)
  return rows
end

local rows = run("laps { laps = 2 }", "laps { laps = 4 }", 2)
expect.eq(rows[1].laps, 4, "more laps: the race went longer")

rows = run("laps { laps = 5 }", "laps { laps = 1 }", 3)
expect.eq(rows[1].laps, 2, "fewer laps than done: the leader's next crossing ended it")

rows = run("laps { laps = 2 }", "timed { minutes = 10 }", 2)
expect.eq(rows[1].laps, 2, "another kind of session: refused, the race went on as laps")
for _, row in ipairs(rows) do expect.eq(row.finished, "true", "every car finished") end
