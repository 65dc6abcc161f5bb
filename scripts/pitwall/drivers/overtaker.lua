-- pitwall.drivers.overtaker: cruises in its lane and passes slower cars in another
-- (docs/racing.md "Drivers").
--
--   overtaker.new{speed = 1000, lanes = {-68, 68}, margin = 250, range = 900, slower = 50,
--                 gap = 0.4, lateralSpeed = 500, …}
--
-- lanes[1] is its lane, lanes[2] the passing lane. Its speed is a follower's (gap `gap` s to
-- whatever is ahead in the lanes it is in or moving to; the other options go to it), so it never
-- runs into a car it cannot pass. When a car at least `slower` mm/s slower than `speed` is
-- within `range` mm ahead in its lane, and no car is in the passing lane or between the lanes
-- from `margin` mm behind (more for a faster car coming: what it gains while we pass) to `margin` mm
-- past that car, nor a car slower than `speed` up to `range` mm further, it changes to the
-- passing lane. Once the passed car is `margin` mm behind and its own lane is
-- clear from `margin` behind to `margin` ahead, it changes back. `driver.passes` counts them.
-- A car not in lanes[1] (it started elsewhere, was moved) goes there when that is clear.
local drivers = require "pitwall.drivers"
local follower = require "pitwall.drivers.follower"

local overtaker = { name = "overtaker" }
local Overtaker = {}
Overtaker.__index = Overtaker
Overtaker.__name = "overtaker" -- (how errors name it: "overtaker has no method …")

--- Its options and the follower's inside it (docs/racing.md "The drivers").
overtaker.options = drivers.optionList({ "lanes", "margin", "range", "slower", "lateralSpeed",
  "gap" }, follower.options)

function overtaker.new(options)
  options = options or {}
  drivers.checkOptions("overtaker.new", options, overtaker.options)
  local o = drivers.pick(options, follower.options)
  o.gap = o.gap or 0.4
  local lanes = options.lanes or { -68, 68 }
  return setmetatable({
    name = "overtaker",
    home = lanes[1], pass = lanes[2],
    margin = options.margin or 250,
    range = options.range or 900,
    slower = options.slower or 50,
    lateral = options.lateralSpeed or 500,
    follow = follower.new(o),
    state = "home", -- "home", "out" (in or going to the passing lane), "back"
    passes = 0,
  }, Overtaker)
end

local WIDTH = 45 -- mm: offsets closer than this share a lane (the simulator: 40 mm)

-- Is any car in the lanes from `from` to `to` — leaving out the lane `from` itself — with a
-- gap in [behind, ahead], or in (ahead, further] and not faster than `speed`? A faster car
-- from behind needs more room: what it gains on us in `stay` s (default 1.5), at the larger of
-- its speed and the speed it was told to drive.
local function occupied(ctx, from, to, behind, ahead, speed, further, stay)
  further = further or ahead
  local lo, hi = math.min(from, to) - WIDTH, math.max(from, to) + WIDTH
  for _, o in ipairs(ctx:nearby(math.max(-behind, further) + 600)) do
    if o.lane and o.lane >= lo and o.lane <= hi and math.abs(o.lane - from) >= WIDTH then
      local v = o.loc.speed or 0
      -- behind: the speed it is heading for counts (pitwall commands every car of a race)
      local coming = math.max(0, math.max(v, o.car.targetSpeed or 0) - speed) * (stay or 1.5)
      if o.gap >= behind - coming and o.gap <= ahead then return o end
      if o.gap > ahead and o.gap <= further and v < speed then return o end
    end
  end
  return nil
end

function Overtaker:start(car, ctx) self.state = "home" end

-- A reload swaps the driver (docs/racing.md "Drivers across a reload"): a pass under way goes
-- on, and the count of passes with it.
function Overtaker:handover()
  return { state = self.state, passing = self.passing, passes = self.passes,
    follow = self.follow:handover() }
end

function Overtaker:takeover(car, ctx, state, from)
  if from ~= "overtaker" or type(state) ~= "table" then return end
  self.state, self.passing, self.passes = state.state or "home", state.passing, state.passes or 0
  self.follow:takeover(car, ctx, state.follow, "follower")
end

-- Seconds it will spend in the passing lane to pass `lead` at `speed`, lane changes included.
-- Speeds are along lanes: the gain along the centre line is taken as a lap's average (in a
-- curve the outer lane gains less, or loses).
function Overtaker:passTime(ctx, lead, speed)
  local map, centre = ctx.map, ctx.map:lapLength(0)
  local ours = speed * centre / map:lapLength(self.pass)
  local theirs = (lead.loc.speed or 0) * centre / map:lapLength(self.home)
  local gain = math.max(ours - theirs, self.slower)
  local across = 2 * math.abs(self.pass - self.home) / self.lateral -- out and back
  return (lead.gap + 2 * self.margin) / gain + across + 0.5
end

function Overtaker:update(car, ctx)
  local speed = drivers.cap(ctx, self.follow.cruise.speed)
  local m = self.margin
  if self.state == "home" and not drivers.changing(car) and car.offset
    and math.abs(car.offset - self.home) > 10 and drivers.moving(car) then
    -- Not in its lane (it started elsewhere, or was moved): go there when it is clear.
    if not occupied(ctx, car.offset, self.home, -m, m, car.speed or 0) then
      car:changeLane(self.home, self.lateral)
      self.state = "back"
    end
  elseif self.state == "home" and not drivers.changing(car) then
    local lead = drivers.aheadIn(ctx, self.home, self.range)
    if lead and (lead.loc.speed or 0) < speed - self.slower and drivers.moving(car)
      and not occupied(ctx, self.home, self.pass, -m, lead.gap + m, speed,
        lead.gap + m + self.range, self:passTime(ctx, lead, speed)) then
      car:changeLane(self.pass, self.lateral)
      self.state, self.passing = "out", lead.car
    end
  elseif self.state == "out" then
    local behind = true
    for _, o in ipairs(ctx:nearby(ctx.map:lapLength(0) / 2 - 1)) do
      if o.car == self.passing and o.gap > -m then behind = false end
    end
    -- back home once past, while the car rolls (one that stands takes no lane change)
    if behind and not drivers.changing(car) and drivers.moving(car)
      and not occupied(ctx, self.pass, self.home, -m, m, car.speed or 0) then
      car:changeLane(self.home, self.lateral)
      self.state = "back"
      self.passes = self.passes + 1
    end
  elseif self.state == "back" and not drivers.changing(car) then
    self.state, self.passing = "home", nil
  end
  self.follow:update(car, ctx)
end

return overtaker
