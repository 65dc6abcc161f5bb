-- The start of a session for pitwall.race (docs/racing.md "What a session does", steps 2 and 3):
-- the cars to the grid, each in a lane of its own, then the start lights with false starts.
-- These are methods of a session; race.lua takes them in.
local localize = require "pitwall.localize"
local drivers = require "pitwall.drivers"

local Start = {}

local LANES = { -68, -23, 23, 68 }

-- Why a car did not reach the grid, for the error.
function Start:_gridProblem(e)
  local car, loc, n = e.car, e.loc, #self.map.pieces
  if not car.connected then return "it is not connected" end
  if not loc.localized then
    return "its place on the map is not known (no position updates: is it on the track?)"
  end
  local where = string.format("on piece %d of %d (id %d) in lane %s at %d mm/s", loc.index, n,
    self.map.pieces[loc.index].id, tostring(loc.lane), math.floor((car.speed or 0) + 0.5))
  local me = loc:distance()
  for _, o in ipairs(self.order) do
    local d = o ~= e and o.loc.localized and o.loc:distance()
    if d and me and o.loc.lane == loc.lane then
      local gap = (d - me) % self.map:lapLength(0)
      if gap < 400 then
        return string.format("%s, %.0f mm behind %s in the same lane", where, gap, tostring(o.car))
      end
    end
  end
  return where .. ((car.speed or 0) == 0 and ", standing still" or "")
end

-- Drives cars that are known to be elsewhere to the grid (the map's last piece, before the line:
-- 34, or on a track without the start piece the one before the line the map has) and stops
-- them there. Cars
-- are given lanes of their own (those already on the grid keep theirs; the others take the
-- free lane nearest to theirs), so two cars in one lane do not end up one behind the other.
function Start:_toGrid()
  local n = #self.map.pieces
  local gridId = self.map.pieces[n].id
  local moving, taken = {}, {}
  for _, e in ipairs(self.order) do
    -- elsewhere: localized on another piece; or, not localized, its last position update on a
    -- piece with another id, or a transition after it (it has left that piece). A car that has
    -- not reported where it is stands where it was put: on the grid.
    local elsewhere
    if e.loc.index then
      elsewhere = e.loc.index ~= n
    elseif self.lastKind[e.car] == "transition" then
      elsewhere = true
    else
      elsewhere = e.car.piece ~= nil and e.car.piece ~= gridId
    end
    if elsewhere and e.car.connected then
      moving[#moving + 1] = e
    else
      taken[localize.nearestLane(e.car.offset or 0)] = e
    end
  end
  if #moving == 0 then
    -- a version that took the session up while the cars were settling waits out the rest
    local left = (self.settleUntil or 0) - pitwall.now()
    if left > 0 then pitwall.sleep(left) end
    return
  end
  local names = {}
  for _, e in ipairs(moving) do names[#names + 1] = e.car.name end
  local waiting = #self.order - #moving
  pitwall.log("info", string.format("race: to the grid: %s%s", table.concat(names, ", "),
    waiting > 0 and string.format(" (%d on it already)", waiting) or ""))
  -- A car's lane is known once it reports a position on the way (one that was put somewhere
  -- by hand has not reported where): then it is given the free lane nearest to its own.
  local began = pitwall.now()
  local function assign(e)
    local here = localize.nearestLane(e.car.offset or 0)
    local lane
    for _, l in ipairs(LANES) do
      if not taken[l] and (not lane or math.abs(l - here) < math.abs(lane - here)) then lane = l end
    end
    lane = lane or here -- more cars than lanes: this one queues in its lane
    taken[lane], e.gridLane = e, lane
    if lane ~= here then
      pitwall.log("info", string.format("race: %s moves to lane %d for the grid", tostring(e.car),
        lane))
      e.car:changeLane(lane)
    end
  end
  for _, e in ipairs(moving) do
    e.gridLane = nil
    e.car:setSpeed(self.options.gridSpeed or 500, 1000)
  end
  local timeout = self.options.gridTimeout or 90
  local ok = pitwall.waitUntil(function()
    local all = true
    for _, e in ipairs(moving) do
      if not e.gridLane and (e.car.lastPositionTime or -math.huge) > began then assign(e) end
      if e.loc.localized and e.loc.index == n then
        if e.car.targetSpeed ~= 0 then e.car:stop() end
      else
        all = false
      end
    end
    return all
  end, timeout, 0.005)
  if not ok then
    local why = {}
    for _, e in ipairs(moving) do
      if not (e.loc.localized and e.loc.index == n) then
        why[#why + 1] = tostring(e.car) .. ": " .. self:_gridProblem(e)
        if e.car.connected then pcall(e.car.stop, e.car) end
      end
    end
    pitwall._raise(string.format("race: %d car(s) did not reach the grid (%s) in %g s — %s. "
      .. "The cars are stopped: check that each is on the track and can drive (a car blocked in "
      .. "its lane: put it in a lane of its own), or raise gridTimeout", #why,
      gridId == 34 and "piece 34" or "map piece " .. n .. ", before the line", timeout,
      table.concat(why, "; ")))
  end
  -- settled: a car still rolling at the first light would be a false start
  self.settleUntil = pitwall.now() + 1
  pitwall.sleep(1)
end

-- Lights: `lights` (5) one a second, then out after `hold` s: green. A car that moves meanwhile
-- has jumped the start.
function Start:_lights()
  local o = self.options
  local count, interval, hold = o.lights or 5, o.lightInterval or 1, o.hold or 0.5
  self.state = "lights"
  -- A car that moves (or is told to) has jumped the start: stopped at once, held after green.
  local function judge(e)
    if e.falseStart then return end
    e.falseStart = true
    pitwall.log("warn", string.format("race: false start by %s: held %g s after green",
      tostring(e.car), self.penalty))
    if e.car.connected then pcall(e.car.stop, e.car) end
    self:_emit("onFalseStart", e.car, self)
  end
  local subs = {}
  for _, e in ipairs(self.order) do
    -- a car that moves reports it, one told to move acknowledges the speed (a speed update);
    -- one only told to (targetSpeed) is caught at the next period as well
    local function moved() judge(e) end
    subs[#subs + 1] = pitwall.listen(e.car, "onTransition", moved)
    subs[#subs + 1] = pitwall.listen(e.car, "onPosition", moved)
    subs[#subs + 1] = pitwall.listen(e.car, "onSpeed", function(_, ev)
      if (ev.desired or 0) > 0 then judge(e) end
    end)
  end
  -- Drivers that drive during the lights (driver:waiting: a human's throttle goes through) are
  -- asked every period; what they do is judged like everything else.
  local period, nextWait = self.period or 0.1, -math.huge
  local EPS = 1e-6 -- (times are whole ns: a sleep of 0.1 s may end a hair before now + 0.1)
  local function check()
    local now = pitwall.now()
    if now >= nextWait - EPS then
      nextWait = now + period
      for _, e in ipairs(self.order) do
        if not e.falseStart and e.driver and e.driver.waiting and e.car.connected then
          drivers.call(e.driver, "waiting", e.car, e.ctx)
        end
      end
    end
    for _, e in ipairs(self.order) do
      if (e.car.targetSpeed or 0) > 0 then judge(e) end
    end
  end
  -- A light's time, waking for each period's check (and no more often: the events judge the
  -- cars that move in between), the light's end exactly.
  local function wait(k, spent)
    local deadline = pitwall.now() + math.max(0, (k < count and interval or hold) - spent)
    while true do
      check()
      local now = pitwall.now()
      if now >= deadline - EPS then return end
      pitwall.sleep(math.min(nextWait, deadline) - now)
    end
  end
  -- A version that took the session up during the lights waits out the light that was on.
  local from = self.light or 0
  if from > 0 then wait(from, pitwall.now() - self.lightAt) end
  for k = from + 1, count do
    self.light, self.lightAt = k, pitwall.now()
    pitwall.log("debug", string.format("race: light %d of %d", k, count))
    self:_emit("onLights", k, self)
    if self.board then
      self.board.title = self.title .. "   " .. string.rep("●", k) .. string.rep("○", count - k)
      self.board:show(self:_rows())
    end
    wait(k, 0)
  end
  for _, s in ipairs(subs) do s:cancel() end
  -- Every car stands on the grid (the map's last piece: 34): its tracker knows it from here, so
  -- the line is crossed on its first transition even when it reports no position on the way (a
  -- real car pulling away fast often does not).
  for _, e in ipairs(self.order) do
    if not e.falseStart then e.loc:assume(#self.map.pieces) end
  end
  pitwall.log("debug", "race: green")
end

return Start
