-- The race's marshal (docs/racing.md "What a session does"): a car whose lap is taking far
-- longer than it should is seen, said in the log (and so in the view's event log) and, when it
-- is stuck in a contact, freed. Methods of a session (pitwall.race); no state of its own.
--
-- Slow: a lap under way for more than SLOW times the reference and SLOW_MIN s more — the reference
-- is the car's best lap, else the field's, else a lap at 400 mm/s. Seen once per SLOW·reference
-- while it lasts.
--
-- Stuck in a contact: the car reported a collision during that lap (it ran into a car, or one ran
-- into it). Two AI drivers can hold each other so: a car held behind another, pushing, reports
-- nothing and is reckoned on ahead, and the car in front stands for it (the jam of issue 34). So a
-- stuck car is driven at NUDGE_SPEED at least for NUDGE_FOR s whatever its driver says (the car in
-- front moves, the one behind reads the track again), and one that ran into a car is sent to the
-- nearest lane no other car is reckoned in within FREE mm. A human's car is never driven for its
-- driver: it is only reported. A car slow with no contact (its driver stands it, it is lost) is
-- only reported, with its speed.
--
-- Thrown off a curve: a car that delocalized on a curve and is still on the track (no status
-- "off the track": it slid, as a real car does when it takes a curve a little too fast) is driven
-- on at searchSpeed at most until it is found again, and that curve's limit for it
-- (ctx.pieceLimits, which the shipped drivers keep to) is set to 85 % of the speed it was thrown
-- at, lower each time it is thrown there again. A car off the track (lifted, flown off) is left
-- to the safety caps and to whoever puts it back.
local Marshal = {}

local SLOW = 2.5          -- a lap this many times the reference is slow …
local SLOW_MIN = 3        -- … and at least this many seconds more than it
local NUDGE_SPEED = 300   -- mm/s
local NUDGE_FOR = 2       -- s
local FREE = 600          -- mm either side: a lane with no car reckoned this near is free
local LANES = { -68, -23, 23, 68 }
local SEARCH = 400        -- mm/s: a thrown car is driven at most this fast until it is found
local LOWER = 0.85        -- a curve's limit after a throw: this share of the speed it happened at

-- The lap time a car's laps are measured against.
function Marshal:_reference(e)
  if e.timer.best then return e.timer.best.time end
  local best
  for _, o in ipairs(self.order) do
    local b = o.timer.best and o.timer.best.time
    if b and (not best or b < best) then best = b end
  end
  return best or self.map:lapLength(0) / 400
end

-- The free lane nearest to the car's, or nil.
function Marshal:_freeLane(e)
  local mine = e.car.offset or 0
  local L = self.map:lapLength(0)
  local d = e.loc:distance()
  local best
  for _, lane in ipairs(LANES) do
    if math.abs(lane - mine) > 20 then
      local free = true
      for _, o in ipairs(self.order) do
        local od = o ~= e and o.loc:distance()
        if od and d and math.abs(((od - d + L / 2) % L) - L / 2) < FREE
            and math.abs((o.car.offset or 0) - lane) < 35 then
          free = false
        end
      end
      if free and (not best or math.abs(lane - mine) < math.abs(best - mine)) then best = lane end
    end
  end
  return best
end

-- The map index of the piece at centre-line distance d from the line.
function Marshal:_pieceAt(d)
  for i, p in ipairs(self.map.pieces) do
    if d >= p.start and d < p.start + p.centre then return i end
  end
  return #self.map.pieces
end

-- A car lost on a curve while still on the track: thrown off it. Once per loss.
function Marshal:_thrown(e)
  e.thrownSeen = e.lostAt
  local i = e.lostIndex or self:_pieceAt(e.lostDistance)
  local p = self.map.pieces[i]
  if p.type ~= "curve" then return end
  local speed = math.floor((e.lostSpeed or 0) + 0.5)
  local limit = math.floor(LOWER * speed)
  e.pieceLimits = e.pieceLimits or {}
  if e.pieceLimits[i] then limit = math.min(limit, math.floor(LOWER * e.pieceLimits[i])) end
  e.pieceLimits[i] = limit
  e.searching = true
  local search = self.options.searchSpeed or SEARCH
  local what = string.format("driven at %d mm/s at most until it is found again; it takes "
    .. "that curve at %d mm/s at most from now", search, limit)
  pitwall.log("warn", string.format("race: %s was thrown off piece %d (%s) at %d mm/s: %s",
    tostring(e.car), i, tostring(p), speed, what))
  self:_emit("onThrown", e.car, { piece = i, speed = speed, limit = limit, action = what }, self)
end

-- A lost car is localized again.
function Marshal:_found(e)
  e.lost = false
  if e.searching then
    e.searching = false
    local _, i = e.loc:locate()
    pitwall.log("info", string.format("race: %s found again on piece %s", tostring(e.car),
      tostring(i)))
  end
end

-- Sees slow cars and frees those stuck in a contact; drives thrown cars on slowly. Called every
-- tick while racing, after the safety caps.
function Marshal:_marshal(now)
  if self.state ~= "racing" or self.options.marshal == false then return end
  local search = self.options.searchSpeed or SEARCH
  for _, e in ipairs(self.order) do
    if e.lost and e.lostWhy == "delocalized" and not e.offTrack and e.started and not e.finished
        and e.thrownSeen ~= e.lostAt then
      self:_thrown(e)
    end
    if e.searching and e.lost and not e.offTrack then
      e.limit = math.min(e.limit or search, search)
    end
  end
  for _, e in ipairs(self.order) do
    local start = e.timer.start
    if e.started and not e.finished and e.car.connected and start then
      local ref = self:_reference(e)
      local took = now - start
      if took > SLOW * ref and took > ref + SLOW_MIN
          and (not e.slowAt or now - e.slowAt > SLOW * ref) then
        e.slowAt = now
        self:_slow(e, took, ref, now)
      end
    end
  end
end

function Marshal:_slow(e, took, ref, now)
  local car, loc = e.car, e.loc
  local lap = e.timer.count + 1
  local contact = (loc.hitFromBehind and loc.hitFromBehind >= e.timer.start)
    or (loc.ranInto and loc.ranInto >= e.timer.start)
  local human = e.driver and e.driver.name == "human"
  local what
  if contact and not human then
    e.floor, e.floorUntil = NUDGE_SPEED, now + NUDGE_FOR
    what = string.format("stuck in a contact: driven at %d mm/s for %g s", NUDGE_SPEED, NUDGE_FOR)
    if loc.ranInto and loc.ranInto >= e.timer.start then
      local lane = self:_freeLane(e)
      if lane then
        pcall(car.changeLane, car, lane)
        what = what .. string.format(", and to lane %+d", lane)
      end
    end
  elseif contact then
    what = "stuck in a contact (a human drives it: left to its driver)"
  else
    what = string.format("no contact: its driver asks %d mm/s%s", car.targetSpeed or 0,
      loc.localized and "" or ", and it is not found on the track")
  end
  local text = string.format("race: %s is slow: lap %d has taken %.1f s, %.1f times %.3f s; %s",
    tostring(car), lap, took, took / ref, ref, what)
  pitwall.log("warn", text)
  self:_emit("onSlowLap", car, { lap = lap, took = took, reference = ref, action = what }, self)
end

-- After its driver's update: a car being freed drives at least the nudge speed (the safety
-- limit still wins).
-- A car that reports a contact (0x4d, side 0) while racing with a car reckoned within
-- CONTACT_NEAR mm in an overlapping lane: said in the log and the view's event log — "skull ran into nuke" when nuke
-- is ahead, else "contact: skull and nuke" — once per pair within CONTACT_QUIET s (both cars
-- report the same contact). A report with no car near is none: real cars at speed send one at
-- many piece boundaries (docs/simulator.md), and so does the simulator's real sensor model.
local CONTACT_NEAR = 300  -- mm
local CONTACT_QUIET = 3   -- s
local CONTACT_LANE = 40   -- mm between two cars' lane offsets at most (the lanes are 45 apart)
function Marshal:_contact(e, ev)
  if self.state ~= "racing" or ev.side ~= 0 then return end
  local L = self.map:lapLength(0)
  local mine = e.loc:distance()
  local other, ahead, best
  if mine then
    for _, o in ipairs(self.order) do
      local d = o ~= e and o.loc:distance()
      -- (only a car in an overlapping lane: side by side on the grid is no contact)
      local lane = math.abs((o.car.offset or 0) - (e.car.offset or 0))
      if d and lane < CONTACT_LANE then
        local gap = (d - mine) % L
        local near = math.min(gap, L - gap)
        if near <= CONTACT_NEAR and (not best or near < best) then
          other, ahead, best = o, gap <= L / 2, near
        end
      end
    end
  end
  -- (none near: a report at a boundary with no car there, which real cars send at speed)
  if not other then return end
  local a, b = e.car, other.car
  local key = a.number < b.number and a.number .. ":" .. b.number or b.number .. ":" .. a.number
  self.contacts = self.contacts or {}
  local now = pitwall.now()
  if self.contacts[key] and now - self.contacts[key] < CONTACT_QUIET then return end
  self.contacts[key] = now
  local text
  if ahead and ev.where == "back" then text = a.name .. " ran into " .. b.name
  else text = a.name .. " and " .. b.name end
  pitwall.log("info", "race: contact: " .. text)
  pcall(pitwall.view.event, "contact: " .. text)
end

function Marshal:_applyFloor(e, now)
  if not e.floorUntil then return end
  if now >= e.floorUntil then e.floor, e.floorUntil = nil, nil return end
  local v = e.floor
  if e.limit then v = math.min(v, e.limit) end
  if (e.car.targetSpeed or 0) < v then pcall(e.car.setSpeed, e.car, v, 1000) end
end

return Marshal
