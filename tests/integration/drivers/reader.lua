-- A driver that reads the race as its world sees it, for tests/integration/driver_worlds_test.sh:
-- ctx.race each time it changes ("race view: racing 1:0 2:1 …", car:laps in race order) and the
-- first car ctx:ahead() finds (the world follows the other cars from that first ask on). It
-- drives as the cruiser.
local cruiser = require "pitwall.drivers.cruiser"

local Reader = {}
Reader.__index = Reader

function Reader:update(car, ctx)
  self.inner:update(car, ctx)
  local parts = {}
  for _, s in ipairs(ctx.race.standings) do
    parts[#parts + 1] = string.format("%d:%d", s.car.number, s.laps)
  end
  local line = ctx.race.phase .. " " .. table.concat(parts, " ")
  if line ~= self.seen then
    self.seen = line
    print("race view: " .. line)
  end
  local ahead = ctx:ahead()
  if ahead and not self.sawAhead then
    self.sawAhead = true
    print(string.format("ahead: car %d, %.0f mm", ahead.car.number, ahead.gap))
  end
end

return { name = "reader", new = function()
  return setmetatable({ inner = cruiser.new { speed = 800 } }, Reader)
end }
