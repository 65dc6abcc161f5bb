-- pitwall.drivers.cruiser: drives at a target speed, slower in curves (docs/racing.md "Drivers").
--
--   cruiser.new{speed = 1000, lateral = 7000, accel = 2000, decel = 5000}
--
-- On straights it drives `speed`; in a curve at most √(lateral · r), r the curve's radius in
-- the car's lane (the simulator delocalizes a car above v²/r = 9000 mm/s²), and before a curve it
-- brakes at `decel` in time to enter at that speed; a curve in ctx.pieceLimits (map index →
-- mm/s: where the race saw the car thrown off) at most that. ctx.limit caps everything. Other
-- drivers use it for their speed: cruiser:target(car, ctx) → the speed it would drive now.
local drivers = require "pitwall.drivers"

local cruiser = { name = "cruiser" }
local Cruiser = {}
Cruiser.__index = Cruiser
Cruiser.__name = "cruiser" -- (how errors name it: "cruiser has no method …")

--- Its options (docs/racing.md "The drivers"); other keys are refused as typos.
cruiser.options = { "speed", "lateral", "accel", "decel" }

function cruiser.new(options)
  options = options or {}
  pitwall._checkOptionsOf("cruiser.new", options, cruiser.options)
  return setmetatable({
    name = "cruiser",
    speed = options.speed or 1000,
    lateral = options.lateral or 7000,
    accel = options.accel or 2000,
    decel = options.decel or 5000,
  }, Cruiser)
end

-- The smallest radius of curve `p` over the lanes the car is in or moving to.
local function laneRadius(p, car)
  local side = p.turn == "left" and 1 or -1
  local o = car.offset or 0
  local r = p.radius + side * o
  if drivers.changing(car) and car.targetOffset then
    r = math.min(r, p.radius + side * car.targetOffset)
  end
  return math.max(r, 50)
end

--- The speed to drive now (mm/s), and whether it is a braking one.
function Cruiser:target(car, ctx)
  local v = drivers.cap(ctx, self.speed)
  local loc = ctx.loc
  local d, i = loc:locate()
  if not d then
    -- Not localized (before the first position): a speed safe in any lane of a 280 mm curve.
    return math.min(v, math.sqrt(self.lateral * (280 - 68))), false
  end
  local now = math.max(car.speed or 0, loc.speed or 0)
  local reaction = now * (ctx.period + 0.05) + 20
  local horizon = reaction + (now * now) / (2 * self.decel) + 600
  local braking = false
  local dist = 0 -- centre-line mm from us to the start of the piece looked at
  for k, p in ipairs(ctx:upcoming(horizon)) do
    if k == 1 then
      dist = -(d - p.start) % ctx.map:lapLength(0)
      if dist > 0 then dist = dist - ctx.map:lapLength(0) end
    end
    if p.type == "curve" and p.radius then
      local vc = math.sqrt(self.lateral * laneRadius(p, car))
      -- a piece the car was thrown off has a limit of its own (ctx.pieceLimits, the race's)
      local own = ctx.pieceLimits and ctx.pieceLimits[p.index]
      if own and own < vc then vc = own end
      if dist <= 0 then
        if vc < v then v, braking = vc, true end
      else
        local room = dist - reaction
        local reachable = room > 0 and math.sqrt(vc * vc + 2 * self.decel * room) or vc
        if reachable < now and vc < v then v, braking = vc, true end
        if reachable < v and not braking then v = math.max(vc, reachable) end
      end
    end
    dist = dist + p.centre
  end
  return v, braking
end

function Cruiser:update(car, ctx)
  local v, braking = self:target(car, ctx)
  local accel = (braking or v < (car.targetSpeed or 0)) and self.decel or self.accel
  drivers.setSpeed(car, v, accel)
end

return cruiser
