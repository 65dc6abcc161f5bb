-- pitwall.drivers.follower: cruises, but keeps at least `gap` seconds behind the car ahead in its
-- lane (docs/racing.md "Drivers").
--
--   follower.new{gap = 1.0, speed = 1000, margin = 0.1, standstill = 100, decel = 6000, …}
--
-- Its free speed is a cruiser's (the other options go to it: lateral, accel). With a car ahead
-- in its lane (within 45 mm of its offset) it drives at most (d − standstill) / (gap·(1+margin)),
-- d the smaller of the centre-line distance now and one update + 50 ms from now (as reckoned);
-- below 60 mm/s it stops, and drives off again from 120 mm/s. At a steady speed behind a steady
-- car that is a time gap of gap·(1+margin) plus standstill / speed, so the time gap (distance /
-- own speed) stays above `gap` while it closes, brakes, follows and stops, and it speeds up
-- again as the gap opens. The car it follows stays its leader while in its lane even when
-- reckoned a little behind, and a car that ran into it from behind stays behind for a while even
-- when reckoned a little ahead (cars in one lane cannot pass each other: Follower:leader).
local drivers = require "pitwall.drivers"
local cruiser = require "pitwall.drivers.cruiser"

local follower = { name = "follower" }
local STICKY = 500 -- mm: how far behind a followed car in our lane may be reckoned
local STICKY_FOR = 2 -- s: how long a car that ran into us stays behind us whatever is reckoned
local INTO_LANE = 60 -- mm across: a car this near our offset can run into us (lanes are 45 apart)
local SILENT = 1 -- s without a position update or transition: a car that is not moving
local Follower = {}
Follower.__index = Follower
Follower.__name = "follower" -- (how errors name it: "follower has no method …")

--- Its options and the cruiser's inside it (docs/racing.md "The drivers").
follower.options = drivers.optionList({ "gap", "margin", "standstill", "range", "accel", "decel" },
  cruiser.options)

function follower.new(options)
  options = options or {}
  drivers.checkOptions("follower.new", options, follower.options)
  local o = drivers.pick(options, cruiser.options)
  o.decel = o.decel or 6000
  return setmetatable({
    name = "follower",
    gap = options.gap or 1.0,
    margin = options.margin or 0.1,
    standstill = options.standstill or 100,
    decel = o.decel,
    accel = options.accel or 2000,
    range = options.range,
    cruise = cruiser.new(o),
  }, Follower)
end

--- The car this follower keeps its gap to (from ctx:nearby), or nil.
---
--- Cars in one lane cannot pass through each other: what the trackers reckon between reports
--- can say otherwise until the next report puts it right. So the order last known stands for up
--- to STICKY_FOR s while the reckoning is within STICKY mm of it: the car we followed, reckoned a
--- little behind us (our own speed update lost, say, so our tracker drives on while we stand), is
--- still just ahead; and a car known to be behind us — it ran into us from behind — reckoned a
--- little ahead is still behind. A car held behind us, pushing, is reckoned on at the speed it
--- was told; taken for a leader, it held the follower, which held it: both crawled for a whole
--- grand prix (issue 34's jam, drivers_follower_jam_test.lua).
function Follower:leader(car, ctx)
  local half = ctx.map:lapLength(0) / 2 - 1
  local range = math.min(self.range or math.max(2000, 3 * self.gap * self.cruise.speed), half)
  local now, mine = pitwall.now(), car.offset or 0
  local inLane = function(o) return o.lane and math.abs(o.lane - mine) < 45 end
  self.behind = self.behind or {}
  local hit = ctx.loc.hitFromBehind
  if hit and hit ~= self.hitSeen and now - hit <= STICKY_FOR then
    -- the car that ran into us, whatever its reckoning says along: the one that reported
    -- running into a car as we reported being hit; else, of those reckoned within STICKY, the
    -- nearest across, by the lane it is heading for (one changing into our lane is between
    -- two). Until we are localized (a hit at the start) it is asked again each update.
    local nearest, nearestAcross
    for _, o in ipairs(ctx:nearby(STICKY)) do
      local ran = o.loc.ranInto
      if ran and math.abs(ran - hit) < 0.05 then nearest, nearestAcross = o, -1 break end
      local lane = drivers.changing(o.car) and o.car.targetOffset or o.lane
      local across = lane and math.abs(lane - mine) or math.huge
      if across < INTO_LANE and (not nearest or across < nearestAcross) then
        nearest, nearestAcross = o, across
      end
    end
    if nearest then
      self.hitSeen = hit
      self.behind[nearest.car] = hit
      if self.lastLead == nearest.car then self.lastLead = nil end
    end
  end
  -- behind: for STICKY_FOR s, and then while it reads nothing of the track for SILENT s (a car
  -- held behind us, pushing, reports nothing: its reckoning is no news)
  local function knownBehind(o)
    local t = self.behind[o.car]
    return t ~= nil and o.gap < STICKY
      and (now - t <= STICKY_FOR or now - (o.loc.seenAt or -math.huge) > SILENT)
  end
  local lead = drivers.aheadIn(ctx, mine, range, nil, knownBehind)
  if drivers.changing(car) and car.targetOffset then
    local other = drivers.aheadIn(ctx, car.targetOffset, range, nil, knownBehind)
    if other and (not lead or other.gap < lead.gap) then lead = other end
  end
  local last = self.lastLead
  if last and not (lead and lead.car == last) then
    for _, o in ipairs(ctx:nearby(STICKY)) do
      if o.car == last and o.gap <= 0 and inLane(o) then
        lead = { car = o.car, loc = o.loc, gap = 0, lane = o.lane }
      end
    end
  end
  self.lastLead = lead and lead.car
  return lead
end

--- The speed to drive now, and whether it is braking for the car ahead or a curve.
function Follower:target(car, ctx)
  local v, braking = self.cruise:target(car, ctx)
  local lead = self:leader(car, ctx)
  if lead then
    -- Where both will be one update and the link's latency from now, as the trackers reckon
    -- (they follow speed updates, so a car that brakes is seen braking).
    local t = pitwall.now() + ctx.period + 0.05
    local a, b = lead.loc:distance(t), ctx.loc:distance(t)
    local d = (a and b) and (a - b) % ctx.map:lapLength(0) or lead.gap
    d = math.min(d, lead.gap) -- the gap must hold now and then
    local allowed = math.max(0, (d - self.standstill) / (self.gap * (1 + self.margin)))
    -- Below 60 mm/s it stops (a slow car reports its position seldom, and its tracker may
    -- miss a lost speed update); stopped, it drives off again from 120 mm/s (no creeping).
    if allowed < (self.held and 120 or 60) then allowed = 0 end
    self.held = allowed == 0
    if allowed < v then v, braking = allowed, true end
  else
    self.held = false
  end
  return v, braking
end

-- A reload swaps the driver (docs/racing.md "Drivers across a reload"): what it follows is
-- handed to its successor.
function Follower:handover()
  return { lastLead = self.lastLead, held = self.held }
end

function Follower:takeover(car, ctx, state, from)
  if from ~= "follower" or type(state) ~= "table" then return end
  self.lastLead, self.held = state.lastLead, state.held
end

function Follower:update(car, ctx)
  local v, braking = self:target(car, ctx)
  local last = car.targetSpeed or 0
  local accel = v < last and self.decel or self.accel
  -- Slowing down is sent at once (10 mm/s steps); speeding up in steps of 40 mm/s, so a
  -- steady follow does not send a frame every update.
  drivers.setSpeed(car, v, accel, v > last and 40 or 10)
end

return follower
