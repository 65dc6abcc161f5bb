-- pitwall.drivers.lanekeeper: keeps the car in a lane, another driver drives the speed
-- (docs/racing.md "Drivers").
--
--   lanekeeper.new{offset = 23, tolerance = 10, driver = <driver, class or name>, …}
--
-- Composition: the lane keeper holds an inner driver (default: a cruiser made with the same
-- options) and calls its start, update and finish, then looks after the lane: when the car is
-- (or is heading) more than `tolerance` mm off `offset` — it drifted, was moved, or someone
-- asked for another lane — it changes back to `offset`. It asks again at most every `retry` s
-- (default 1) while the car does not get there.
local drivers = require "pitwall.drivers"

local lanekeeper = { name = "lanekeeper" }
local Keeper = {}
Keeper.__index = Keeper
Keeper.__name = "lanekeeper" -- (how errors name it: "lanekeeper has no method …")

--- Its own options; those of the driver inside it (a cruiser by default) are taken too.
lanekeeper.options = { "driver", "offset", "tolerance", "retry", "lateralSpeed" }

function lanekeeper.new(options)
  options = options or {}
  local inner = options.driver or "cruiser"
  if type(inner) == "string" or (type(inner) == "table" and not inner.update) then
    local cls = drivers.load(inner)
    if type(cls.options) == "table" then -- (a class of the script's own may not list them)
      drivers.checkOptions("lanekeeper.new", options, drivers.optionList(lanekeeper.options,
        cls.options))
      inner = cls.new(drivers.pick(options, cls.options))
    else
      inner = cls.new(options)
    end
  else
    drivers.checkOptions("lanekeeper.new", options, lanekeeper.options)
  end
  return setmetatable({
    name = "lanekeeper",
    offset = options.offset or 23,
    tolerance = options.tolerance or 10,
    retry = options.retry or 1,
    lateral = options.lateralSpeed or 300,
    inner = inner,
    asked = nil, -- time of the last changeLane we sent
  }, Keeper)
end

function Keeper:start(car, ctx)
  if self.inner.start then self.inner:start(car, ctx) end
end

function Keeper:finish(car, ctx)
  if self.inner.finish then self.inner:finish(car, ctx) end
end

-- A reload swaps the driver (docs/racing.md "Drivers across a reload").
function Keeper:handover()
  return { asked = self.asked, inner = self.inner.handover and self.inner:handover() or nil,
    innerName = self.inner.name }
end

function Keeper:takeover(car, ctx, state, from)
  if from == "lanekeeper" and type(state) == "table" then
    self.asked = state.asked
    if self.inner.takeover then self.inner:takeover(car, ctx, state.inner, state.innerName) end
  elseif self.inner.takeover then
    self.inner:takeover(car, ctx, state, from)
  end
end

function Keeper:update(car, ctx)
  self.inner:update(car, ctx)
  if not drivers.moving(car) or car.offset == nil then return end -- lane changes need motion
  local heading = drivers.changing(car) and car.targetOffset or car.offset
  if math.abs(heading - self.offset) <= self.tolerance then return end
  local now = pitwall.now()
  -- A change to another lane under way (not ours): answer at once; else ask every `retry` s.
  if self.asked and now - self.asked < self.retry and not drivers.changing(car) then return end
  car:changeLane(self.offset, self.lateral)
  self.asked = now
end

return lanekeeper
