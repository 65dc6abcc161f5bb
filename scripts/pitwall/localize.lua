-- pitwall.localize: where a car is on a track map, kept up to date from its events
-- (docs/racing.md "Localization").
--
--   local localize = require "pitwall.localize"
--   local loc = localize.follow(car, map)      -- map from pitwall.track
--   loc:distance()    -- centre-line mm from the finish line, now (0 … map:lapLength(0))
--   loc:fraction()    -- the same as a fraction of the lap
--   loc.index, loc.lane, loc.speed, loc.reverse, loc.localized
--
-- Dead reckoning, corrected by every event: between events the car moves on by its reported
-- speed (and, after a speed update said where it is heading, by the asked acceleration); a
-- transition puts it at the start of the next piece; a position update names the piece it is
-- on. Distances are measured along the centre line like the simulator's lap distance: a car
-- that has driven 40 % of a curve's lane is at 40 % of the curve's centre length.
--
-- Position updates carry only a piece id: the piece is the one with that id ahead in driving
-- order whose place fits the reckoning, so pieces that occur several times are told apart by
-- the sequence, and lost frames (a transition, every position on a piece) are bridged. A map
-- piece whose id a scan never saw (track.scan of a car that sent no position update on it) fits
-- any id of its kind (Map:fits). A car
-- that is not localized (at the start, after it left the track or was lifted, or when its ids
-- stop fitting the map) follows every piece that carries its id as a hypothesis through the
-- next events, dropping those that stop fitting, until one remains; the pieces it drove
-- meanwhile are then reported in order.
local localize = {}

local MAX_SKIP = 4        -- pieces a position update may lie ahead when frames were lost
local TWIN_MARGIN = 120   -- mm past a piece's end before the next piece with the same id wins
local SLACK = 120         -- mm a position may lie off the reckoning (plus 30 % of the travel)
local MAX_ACCEL = 25000   -- mm/s²: what an asked acceleration of 0 means (anki-overdrive.md)
local SPEED_MISMATCH = 150 -- mm/s: a reported speed this far off the model switches it off
local LONG_GAP = 1.5       -- s without events after which the reckoning is not trusted (a
                           -- stop and restart the car did not report with a speed update)

local Tracker = {}
Tracker.__index = Tracker
Tracker.__name = "tracker" -- (how errors name it: "tracker has no method …")

local followed = setmetatable({}, { __mode = "k" }) -- car → { [map] = tracker }

local abs = math.abs

--- The lane offset (−68, −23, 23, 68 mm) nearest to `offset`.
function localize.nearestLane(offset)
  -- The lanes −68, −23, 23, 68 (engine/sim/grid.hpp kLaneOffsets, anki-overdrive.md), one by one
  -- (every frame asks): the first of two as near wins, NaN gives the first.
  local best, near = -68, abs(-68 - offset)
  local d = abs(-23 - offset)
  if d < near then best, near = -23, d end
  d = abs(23 - offset)
  if d < near then best, near = 23, d end
  if abs(68 - offset) < near then best = 68 end
  return best
end

-- Lane mm covered in dt s starting at speed v, heading for `target` at `accel` (nil: constant).
local function motion(v, target, accel, dt)
  if dt <= 0 then return 0 end
  if not target or v == target then return v * dt end
  local reach = math.abs(target - v) / accel
  if dt <= reach then
    local a = target > v and accel or -accel
    return v * dt + 0.5 * a * dt * dt
  end
  return (v + target) / 2 * reach + target * (dt - reach)
end

local function speedAfter(v, target, accel, dt)
  if not target or dt <= 0 then return v end
  if target > v then return math.min(target, v + accel * dt) end
  return math.max(target, v - accel * dt)
end

function Tracker:_dir() return self.reverse and -1 or 1 end

-- The lane length of every map piece at the car's offset (map frame: mirrored when reversed),
-- summed again only when the offset, the direction or the map's count of pieces changed (a car
-- keeps its lane for most frames).
function Tracker:_lengths()
  local off = self.reverse and -self.offset or self.offset
  local lens, pieces = self._laneLens, self.map.pieces
  if lens and self._laneOff == off and lens.n == #pieces then return lens end
  lens = lens or {}
  for k, p in ipairs(pieces) do lens[k] = p:length(off) end
  lens.n = #pieces
  self._laneLens, self._laneOff = lens, off
  return lens
end

-- Lane length of piece i at the car's offset (map frame: mirrored when reversed).
function Tracker:_len(i)
  return self:_lengths()[i]
end

-- Lane mm travelled from the last position/transition update until time t.
function Tracker:_travel(t)
  if t <= self.modelTime then return self.carry end
  local target, accel = self.target, self.accel
  if not target then
    -- No speed update to go by (older firmware): a car told to slow down is taken to brake
    -- hard rather than to roll on; the next event tells where it really is.
    local commanded = self.car.targetSpeed
    if commanded and commanded < self.modelSpeed then target, accel = commanded, MAX_ACCEL end
  end
  return self.carry + motion(self.modelSpeed, target, accel, t - self.modelTime)
end

-- After an update at time t: the reckoning starts again from there at `speed`.
function Tracker:_rebase(t, speed)
  local v = speed or speedAfter(self.modelSpeed, self.target, self.accel, t - self.modelTime)
  self.time, self.modelTime, self.carry = t, t, 0
  self._mt = nil
  self.modelSpeed, self.speed = v, v
end

function Tracker:_notify(kind, ...)
  for _, w in ipairs(self.watchers) do
    if w[kind] then w[kind](self, ...) end
  end
end

-- An estimate `e` (the tracker itself, or a hypothesis while it is not localized) entered
-- piece i from piece `from` at time t. Hypotheses keep a list; the tracker tells its watchers.
function Tracker:_entered(e, i, from, t)
  if e.entered then
    e.entered[#e.entered + 1] = { i, from, t }
  else
    self:_notify("enter", i, from, t)
  end
end

-- Moves estimate `e` (index, pos = fraction of the piece driven in the driving direction,
-- anchored = pos is known rather than guessed) by an event at time t, `m` lane mm after the
-- last one at t0: a transition (id nil) or a position update on piece `id`. Returns false
-- when the event does not fit the estimate.
function Tracker:_step(e, m, id, t0, t)
  local map, d = self.map, self:_dir()
  local n = #map.pieces
  local laneLens = self:_lengths()
  local len0 = laneLens[e.index]
  local p0 = e.pos * len0
  local r = p0 + m -- reckoned lane mm from the start of the current piece
  -- The pieces from here on and where each starts: the tracker's own two lists, filled anew at
  -- every event (an event is a frame of one car: no table is made for it)
  local idx, start, lens = self._idx, self._start, self._lens
  if not idx then
    idx, start, lens = {}, {}, {}
    self._idx, self._start, self._lens = idx, start, lens
  end
  idx[1], start[1], lens[1] = e.index, 0, len0
  local at, k = len0, e.index
  for j = 2, MAX_SKIP + 1 do
    k = (k - 1 + d) % n + 1 -- Map:next
    local len = laneLens[k]
    idx[j], start[j], lens[j] = k, at, len
    at = at + len
  end
  local choice, into
  local unsure = t - t0 > LONG_GAP
  if not id then
    -- A transition: the boundary nearest to the reckoning (the next one unless frames were
    -- lost, or always the next one while the place in the piece is a guess).
    choice = 2
    if e.anchored and not unsure then
      for j = 3, MAX_SKIP + 1 do
        if math.abs(r - start[j]) < math.abs(r - start[choice]) then choice = j end
      end
    end
    into = 0
  else
    local best, bestDist
    for j = 1, MAX_SKIP + 1 do
      if map:fits(idx[j], id) then
        local lo, hi = start[j], start[j] + lens[j]
        if j == 1 then
          hi = hi + TWIN_MARGIN
          if not e.anchored then lo = -math.huge end
        end
        local dist = r < lo and lo - r or r > hi and r - hi or 0
        if unsure then dist = 0 end -- the first piece with the id, in order
        if not bestDist or dist < bestDist then best, bestDist = j, dist end
      end
    end
    if not best or bestDist > SLACK + 0.3 * m then return false end
    choice = best
    into = math.max(0, math.min(r - start[choice], lens[choice]))
  end
  for j = 2, choice do
    local when = t
    if (id or j < choice) and m > 0 then
      when = t0 + (t - t0) * math.max(0, math.min(1, (start[j] - p0) / m))
    end
    self:_entered(e, idx[j], idx[j - 1], when)
  end
  e.index = idx[choice]
  e.pos = into / lens[choice]
  if not id then e.anchored = true end
  return true
end

function Tracker:_lose(t, why)
  local was = self.index
  -- where it was reckoned when it was lost (a car thrown off a curve: that curve)
  local _, at = self:locate(t)
  self.index, self.localized, self.anchored = nil, false, false
  self.hyps, self.entrySeen, self._mt = nil, false, nil
  if was then self:_notify("lost", t, why, at) end
end

-- Moves every hypothesis by an event; keeps those it fits, one per piece (two that arrive on
-- the same piece are one from now on: the one that explains more pieces driven stays).
function Tracker:_stepAll(m, id, t)
  local kept, at = {}, {}
  for _, e in ipairs(self.hyps) do
    if self:_step(e, m, id, self.time, t) then
      local other = at[e.index]
      if not other then
        kept[#kept + 1], at[e.index] = e, #kept + 1
      elseif #e.entered > #kept[other].entered then
        kept[other] = e
      end
    end
  end
  self.hyps = #kept > 0 and kept or nil
end

-- A position update on piece `id` while not localized.
function Tracker:_identify(id, t, m)
  self.sinceEntry = self.sinceEntry + m
  if self.hyps then self:_stepAll(m, id, t) end
  if not self.hyps then
    -- Every piece with this id, at its start or, right after a transition, as far in as the
    -- car has driven since.
    local hyps = {}
    for _, k in ipairs(self.map:candidates(id)) do
      local e = { index = k, pos = 0, anchored = self.entrySeen, entered = { { k, nil, t } } }
      if e.anchored then e.pos = math.min(1, self.sinceEntry / self:_len(k)) end
      hyps[#hyps + 1] = e
    end
    self.hyps = #hyps > 0 and hyps or nil -- none: not a piece of this map
  end
  self.entrySeen = false
  if self.hyps and #self.hyps == 1 then self:_adopt() end
end

-- One hypothesis is left: localized there; what it drove meanwhile is reported in order.
function Tracker:_adopt()
  local e = self.hyps[1]
  self.hyps = nil
  self.index, self.pos, self.anchored, self.localized = e.index, e.pos, e.anchored, true
  for _, x in ipairs(e.entered) do self:_notify("enter", x[1], x[2], x[3]) end
end

--- Takes it that the car stands on map piece `index` though it has not reported where it is (a
--- race director that drove it to the grid knows): if its next event is a transition, that is
--- the end of this piece, and the car is localized on the next one from there. A real car
--- pulling away from the grid at speed may send no position update before the line
--- (docs/simulator.md "Sensor model"). Until then it stays not localized; a position update
--- first drops the hint. Nothing changes for a car already localized.
function Tracker:assume(index)
  if self.localized or not self.map.pieces[index] then return end
  self.grid = index
end

function Tracker:_onPosition(ev)
  local t = ev.time
  self._mt = nil -- (a watcher told of a piece entered asks where the car is now)
  self.seenAt = t -- the car read the track: it moved
  if ev.reverse ~= self.reverse then
    -- A U-turn somewhere since the last update: about as far forth as back, so stay put.
    self.reverse = ev.reverse
    self.pos = 1 - self.pos
    self.hyps = nil -- the ids seen so far came the other way
    self.carry, self.modelSpeed, self.modelTime = 0, 0, t
  end
  local m = self:_travel(t)
  self.grid = nil
  if self.index then
    if not self:_step(self, m, ev.piece, self.time, t) then
      self:_lose(t, "its piece ids stopped fitting the map")
      self:_identify(ev.piece, t, 0)
    end
  else
    self:_identify(ev.piece, t, m)
  end
  -- A car held up (another car in front) does not follow the asked speed: stop modelling it.
  if self.target and math.abs(speedAfter(self.modelSpeed, self.target, self.accel,
      t - self.modelTime) - ev.speed) > SPEED_MISMATCH then
    self.target = nil
  end
  self.offset, self.lane = ev.offset, localize.nearestLane(ev.offset)
  self:_rebase(t, ev.speed)
end

function Tracker:_onTransition(ev)
  local t = ev.time
  self._mt = nil
  self.seenAt = t
  local m = self:_travel(t)
  if self.index then
    self:_step(self, m, nil, self.time, t)
  elseif self.grid then
    -- the end of the piece it was taken to stand on (Tracker:assume)
    local from = self.grid
    local i = self.map:next(from, self:_dir())
    self.grid, self.hyps = nil, nil
    self.index, self.pos, self.anchored, self.localized = i, 0, true, true
    self:_notify("enter", i, from, t)
  elseif self.hyps then
    self:_stepAll(m, nil, t)
    if self.hyps and #self.hyps == 1 then self:_adopt() end
  else
    self.entrySeen, self.sinceEntry = true, 0
  end
  self.offset, self.lane = ev.offset, localize.nearestLane(ev.offset)
  self:_rebase(t, nil)
end

function Tracker:_onSpeed(ev)
  -- The reckoning so far is kept; from now on the car heads for the asked speed.
  local t = ev.time
  local v = ev.actual or speedAfter(self.modelSpeed, self.target, self.accel, t - self.modelTime)
  self.carry = self:_travel(t)
  self.modelTime, self.modelSpeed, self._mt = t, v, nil
  -- Firmware 0x266e's short form says neither the acceleration nor the actual speed: the
  -- reckoning goes on as for a car that sends no speed update (by the commanded speed).
  if not ev.accel then return end
  self.target = ev.desired
  self.accel = ev.accel > 0 and ev.accel or MAX_ACCEL
end

-- The tracker's listeners on its car's events.
local function listenTo(self)
  local car = self.car
  self.subs = {
    pitwall.listen(car, "onPosition", function(_, ev) self:_onPosition(ev) end),
    pitwall.listen(car, "onTransition", function(_, ev) self:_onTransition(ev) end),
    pitwall.listen(car, "onSpeed", function(_, ev) self:_onSpeed(ev) end),
    -- A car run into from behind (the front car's report: side 0, "front") knows a car is right
    -- behind it, whatever that car's reckoning says (drivers.follower uses it).
    pitwall.listen(car, "onCollision", function(_, ev)
      -- (0x4d: "front", a car ran into this one from behind; "back", this one into a car)
      if ev.side == 0 and ev.where == "front" then self.hitFromBehind = ev.time end
      if ev.side == 0 and ev.where == "back" then self.ranInto = ev.time end
    end),
    pitwall.listen(car, "onDelocalized", function(_, ev)
      self:_lose(ev.time, "delocalized")
      self:_rebase(ev.time, 0)
    end),
    pitwall.listen(car, "onStatus", function(_, ev)
      if not ev.onTrack then self:_lose(ev.time, "off the track") end
    end),
    -- Where a car goes while nobody hears from it is unknown.
    pitwall.listen(car, "onDisconnect", function(_, ev)
      self:_lose(ev.time, "disconnected")
      self:_rebase(ev.time, 0)
    end),
  }
end

--- Follows `car` on `map` (a map from pitwall.track) and returns its tracker; the same car and
--- map give the same tracker. options.horizon: how many seconds past the last event the
--- position is extrapolated (default 3; at 300 mm/s two lost frames leave a gap over 1 s).
function localize.follow(car, map, options)
  -- (the tracker it has already: a driver's context asks for every car at every update)
  local known = options == nil and followed[car]
  known = known and known[map]
  if known then return known end
  if type(map) ~= "table" or type(map.pieces) ~= "table" or not map.lapLength then
    pitwall._raise("localize.follow(car, map): map must be a track map from pitwall.track "
      .. "(track.scan or track.fromSim), got " .. type(map))
  end
  pitwall._checkOptionsOf("localize.follow", options, { "horizon" })
  local byMap = followed[car]
  if byMap and byMap[map] then return byMap[map] end
  local now = pitwall.now()
  local self = setmetatable({
    car = car, map = map, localized = false, anchored = false, reverse = false,
    offset = 0, lane = nil, speed = 0, time = now, pos = 0,
    carry = 0, modelTime = now, modelSpeed = 0, sinceEntry = 0, entrySeen = false,
    horizon = options and options.horizon or 3, watchers = {},
  }, Tracker)
  local ok, err = pcall(listenTo, self)
  if not ok then pitwall._rethrow("localize.follow: ", err) end
  followed[car] = byMap or {}
  followed[car][map] = self
  return self
end

--- Takes up a tracker carried from an earlier version of the script (docs/hot-reload.md): its
--- state as it was, following the car again in this version. Its watchers are not carried: who
--- subscribed (a lap timer, a race) subscribes again. The map must have been taken up
--- (track._adopt). Returns the tracker.
function localize._adopt(data)
  if getmetatable(data) == Tracker then return data end
  local byMap = followed[data.car]
  if byMap and byMap[data.map] then return byMap[data.map] end
  setmetatable(data, Tracker)
  data.watchers = {}
  listenTo(data)
  followed[data.car] = byMap or {}
  followed[data.car][data.map] = data
  return data
end

--- Stops following: the tracker's listeners are cancelled.
function Tracker:cancel()
  for _, s in ipairs(self.subs) do s:cancel() end
  if followed[self.car] then followed[self.car][self.map] = nil end
  self.watchers = {}
end

--- Calls handlers.enter(tracker, index, from, time) each time the car is on a new piece
--- (`from` is the previous index, nil when the car was found anew) and handlers.lost(tracker,
--- time, why, index) when it is lost (`index`: the piece it was reckoned on then). Returns a
--- function that ends the subscription.
function Tracker:subscribe(handlers)
  local list = table.move(self.watchers, 1, #self.watchers, 1, {})
  list[#list + 1] = handlers
  self.watchers = list
  return function()
    local kept = {}
    for _, w in ipairs(self.watchers) do
      if w ~= handlers then kept[#kept + 1] = w end
    end
    self.watchers = kept
  end
end

--- Where the car is at time t (default now): centre-line mm from the finish line, the piece
--- index and the fraction of that piece (in the map's direction); nil when not localized.
function Tracker:locate(t)
  if not self.index then return nil end
  t = math.min(t or pitwall.now(), self.time + self.horizon)
  -- The last answer, asked again for the same time (a driver asks, then ctx:upcoming asks): kept
  -- until the car's next event, and — with no speed update to go by — while the car is told the
  -- same speed (Tracker:_travel).
  if self._mt == t and (self.target or self._ms == self.car.targetSpeed) then
    return self._md, self._mi, self._mf
  end
  local i = self.index
  local laneLens = self:_lengths()
  local len = laneLens[i]
  local into = self.pos * len + self:_travel(t)
  for _ = 1, MAX_SKIP do -- on into the next pieces (their frames may have been lost)
    if into <= len then break end
    i, into = self.map:next(i, self:_dir()), into - len
    len = laneLens[i]
  end
  into = math.min(into, len)
  local f = into / len
  if self.reverse then f = 1 - f end
  local p = self.map.pieces[i]
  local d = p.start + f * p.centre
  self._mt, self._md, self._mi, self._mf = t, d, i, f
  self._ms = not self.target and self.car.targetSpeed or nil
  return d, i, f
end

--- The speed the car is reckoned at, at time t (default now): its last reported speed, heading
--- for the speed it was told at the acceleration it was told (mm/s).
function Tracker:speedAt(t)
  t = t or pitwall.now()
  if t <= self.modelTime then return self.modelSpeed end
  return speedAfter(self.modelSpeed, self.target, self.accel, t - self.modelTime)
end

--- Centre-line mm from the finish line at time t (default now), or nil.
function Tracker:distance(t)
  return (self:locate(t))
end

--- The fraction of the lap from the finish line (0 … 1) at time t (default now), or nil.
function Tracker:fraction(t)
  local d = self:locate(t)
  return d and d / self.map:lapLength(0)
end

function Tracker:__tostring()
  local d, i = self:locate()
  if not d then return string.format("%s: not localized", tostring(self.car)) end
  return string.format("%s: piece %d (%s), %.0f of %.0f mm, lane %s", tostring(self.car), i,
    self.map.pieces[i].id or "id unknown", d, self.map:lapLength(0), tostring(self.lane))
end

return localize
