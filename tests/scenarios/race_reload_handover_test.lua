-- A driver whose handover never returns (a bug in the user's driver) costs only its own state: a
-- save mid-race still carries the race — the handover runs after the race's own data is saved,
-- in an engine call of its own, and the callback budget ends it — and the race finishes as one:
-- every line crossing of a car is a lap of this race (no second grid, no second start).
-- tags: race reload
local sim = require "pitwall.sim"

local cars = { sim.addCar {}, sim.addCar {} }
local source = [[
local race = require "pitwall.race"
local D = { name = "looper" }
D.__index = D
function D.new() return setmetatable({}, D) end
function D:update(car, ctx) if car.targetSpeed ~= 600 then car:setSpeed(600, 1000) end end
function D:takeover(car, ctx, state, from) TAKEOVER end
HANDOVER
race.laps { laps = 3, drivers = D, results = RESULTS, board = false }
pitwall.stop()
]]
local results = os.tmpname() .. ".csv"
local function version(handover, takeover)
  return (source:gsub("HANDOVER", handover):gsub("TAKEOVER", takeover)
    :gsub("RESULTS", string.format("%q", results)))
end
local start = {}
for _, c in ipairs(cars) do start[c] = sim.truth(c).laps end
local run = sim.script(version("function D:handover() while true do end end", ""))
-- the new driver gets no state from the looping handover: nil, from "looper"
sim.reload(version("", "assert(state == nil and from == 'looper', 'got ' .. tostring(state))"), 10)
expect.truthy(sim.runUntil(function() return run.finished end, 120), "the race finished")
expect.eq(run.version, 2, "the save took over")
expect.eq(run.errors, 0, "the new driver's takeover got nil from the looping handover")
local f = assert(io.open(results))
f:read("l")
for line in f:lines() do
  local name, laps, finished = line:match("^%d+,([^,]+),%d+,(%d+),[^,]*,[^,]*,[^,]*,(%a+)")
  expect.eq(tonumber(laps), 3, name .. " raced 3 laps")
  expect.eq(finished, "true", name .. " finished")
  for _, c in ipairs(cars) do
    if c.name == name then
      expect.eq(sim.truth(c).laps - start[c], 4, name .. ": 4 crossings, all of one race")
    end
  end
end
f:close()
os.remove(results)
