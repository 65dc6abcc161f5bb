-- In a driver world (docs/drivers.md): the driver its file returned, the context it drives by,
-- and the race director's calls, which come through bindings/driver_world.cpp as
-- pitwall._driverCall(method, car, limit, pieceLimits, period, race, sameRace, map): copies of
-- what drivers.world in the run's world sends — the car (this world's own object of it), ctx's
-- limits and period, the race (phase, standings; nil with sameRace when it is the one sent last)
-- and, on the first call of each world, the map.
local drivers = require "pitwall.drivers"
local track = require "pitwall.track"

local M = {}
local driver, ctx

local METHODS = { start = true, update = true, finish = true, waiting = true }

local function call(method, car, limit, pieceLimits, period, race, sameRace, sentMap)
  if not METHODS[method] then error("no driver method " .. tostring(method), 0) end
  if not ctx then
    local map = sentMap and track._adopt(sentMap)
    if not map then error("the race director sent no map", 0) end
    -- The other cars join the field after the context is made: each is followed from the first
    -- ctx:ahead() or ctx:nearby() on (drivers.context), so a driver that never asks (the
    -- cruiser) pays for no tracker of another car.
    local field = {}
    ctx = drivers.context(car, map, field, { period = period })
    for _, c in ipairs(pitwall.cars()) do -- (a ghost is no one to pass or follow)
      if not c.ghost then field[#field + 1] = c end
    end
  end
  -- ctx.race: a race view the same as the last one is not sent again (drivers.lua's send)
  ctx.limit, ctx.pieceLimits = limit, pieceLimits
  if not sameRace then ctx.race = race end
  local fn = driver[method]
  if fn then fn(driver, car, ctx) end
end

--- The value the driver file returned, `file` its name: a class ({new}, made with no options)
--- or a driver ({update}). Anything else is this world's failure.
function M.setup(value, file)
  if type(value) == "table" and type(value.update) ~= "function" and type(value.new) == "function" then
    value = value.new {}
  end
  if type(value) ~= "table" or type(value.update) ~= "function" then
    error(string.format("%s must return a driver: a class with `new` (as the shipped "
      .. "pitwall/drivers/cruiser.lua does) or a table with an `update` method; it returned %s",
      file, value == nil and "nothing" or "a " .. type(value)), 0)
  end
  driver = value
  pitwall._driverCall = call
end

return M
