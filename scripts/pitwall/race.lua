-- pitwall.race: the race director (docs/racing.md "Races").
--
--   local race = require "pitwall.race"
--   local q = race.qualifying { minutes = 2 }               -- best lap wins
--   local r = race.laps { laps = 5, grid = q, drivers = { "cruiser", "overtaker" } }
--   race.timed { minutes = 3 }   race.practice { minutes = 5 }
--   r:results()   -- {{position, car, number, laps, totalTime, bestLap, lastLap, finished, falseStart}, …}
--
-- Each call runs a whole session inside a task (the main chunk) and returns it when every car
-- has stopped: the map (given, the simulator's, or a scan lap with the first car), the cars to
-- the grid (piece 34), five lights and green (not in practice), drivers updated every period,
-- positions by laps then distance, gaps to the leader, the finish, every car stopped, the final
-- table, and the results file (pitwall.resultsFile). Options and events: docs/racing.md.
local track = require "pitwall.track"
local localize = require "pitwall.localize"
local laps = require "pitwall.laps"
local Board = require "pitwall.board"
local drivers = require "pitwall.drivers"

local race = {}

--- Module-wide handlers, called after a session's own (options.onLap, …):
--- race.onLap(car, lap, session), race.onFinish(car, position, session),
--- race.onPositionChange(car, position, old, session), race.onFalseStart(car, session).
race.onLap, race.onFinish, race.onPositionChange, race.onFalseStart = nil, nil, nil, nil

race.columns = { "position", "car", "number", "laps", "totalTime", "bestLap", "lastLap",
  "finished", "falseStart", "driver", "player", "status", "reason" }

-- A driver that holds one speed (under ctx.limit): the default when no driver is given and
-- pitwall.drivers has no "cruiser".
local Steady = { name = "steady" }
Steady.__index = Steady
Steady.__name = "steady driver" -- (how errors name it: "steady driver has no method …")
function Steady.new(options)
  options = options or {}
  return setmetatable({ speed = options.speed or 600, accel = options.accel or 1000 }, Steady)
end
function Steady:update(car, ctx)
  local v = ctx.limit and math.min(self.speed, ctx.limit) or self.speed
  if car.targetSpeed ~= v then car:setSpeed(v, self.accel) end
end
race.Steady = Steady

--- "1:02.345" from seconds (Board.time).
race.time = Board.time
--- "9.215 s", "1 min 2.345 s" from seconds (Board.duration).
race.duration = Board.duration

--- The sentence that names a session's winner: "Winner: nuke (overtaker), 5 laps in 21.470 s";
--- nil when nobody finished.
function race.winner(session)
  local w = session:results()[1]
  if not w or w.status ~= "finished" then return nil end
  local who = w.player and w.player .. " in " .. w.car or w.car
  if w.driver and not w.player then who = who .. " (" .. w.driver .. ")" end
  return string.format("Winner: %s, %d lap%s in %s", who, w.laps, w.laps == 1 and "" or "s",
    Board.duration(w.totalTime))
end

local Race = {}
Race.__index = Race
Race.__name = "race" -- (a misspelled method names it: "race has no method …")

-- car → the kind of its last event ("position", "transition"): whether car.piece is still
-- where it is (kept for the whole run, from a car's first session on, across reloads)
local lastKind = setmetatable({}, { __mode = "k" })
local listening = setmetatable({}, { __mode = "k" }) -- cars whose kinds this version follows

-- The sessions this version ran, in order; the last map a session raced on. A reload carries
-- them into the new version (docs/hot-reload.md "A race survives a reload"): there the k-th
-- session the script runs takes up the k-th one carried — a finished one returns at once with
-- its results, one under way goes on where it was.
local sessions = {}
local lastMap
local carried = pitwall._takeCarried("race")
if carried ~= nil and (type(carried) ~= "table" or type(carried.sessions) ~= "table") then
  pitwall.log("warn", "race: what the version before carried is not a race library's state ("
    .. type(carried) .. "); the sessions start anew")
  carried = nil
end
carried = carried or { sessions = {} }
if type(carried.lastKind) == "table" then
  for car, kind in pairs(carried.lastKind) do lastKind[car] = kind end
end
if type(carried.map) == "table" and type(carried.map.pieces) == "table" then
  lastMap = track._adopt(carried.map)
end

-- A run that ends while a session races (--duration, Ctrl-C, pitwall.stop() from elsewhere, the
-- --fast cap): the session says where it stood — its final table, its results file.
pitwall._atRunEnd(function()
  for _, session in ipairs(sessions) do
    if session.phase == "racing" or session.phase == "ending" then session:_cut() end
  end
end)

pitwall._carry("race", function()
  local out, kinds = {}, {}
  for k, session in pairs(sessions) do out[k] = session:_carry() end
  -- sessions this version did not take up (not yet, or a version without the race) go on to the
  -- next: a save that briefly empties the script does not lose the race
  for k, c in pairs(carried.sessions) do
    if out[k] == nil then out[k] = c end
  end
  for car, kind in pairs(lastKind) do kinds[car] = kind end
  return { sessions = out, lastKind = kinds, map = lastMap }
end)

local MODES = { practice = "Free practice", qualifying = "Qualifying", laps = "Race",
  timed = "Timed race" }

-- Every option a session takes (docs/racing.md "Options"): any other key is a typo.
race.options = { "mode", "laps", "minutes", "seconds", "cars", "map", "scan", "drivers", "grid",
  "lights", "lightInterval", "hold", "falseStartPenalty", "safety", "cooldown", "finishTimeout",
  "reconnectTimeout", "period", "gridSpeed", "gridTimeout", "board", "title", "redraw", "results",
  "marshal", "searchSpeed", "onLap", "onFinish", "onPositionChange", "onFalseStart", "onLights",
  "onSlowLap", "onThrown", "onEnd" }

local function report(where, err)
  if pitwall._reportError then pitwall._reportError(where, err)
  else pitwall.log("error", where .. ": " .. tostring(err)) end
end

function Race:_emit(name, ...)
  for _, fn in ipairs { self.options[name] or false, race[name] or false } do
    if fn then
      local ok, err = xpcall(fn, pitwall._traceback, ...)
      if not ok then report(name .. " handler of the race", err) end
    end
  end
end

-- A driver instance from a name, a class ({new}), an instance ({update}) or nil.
local function makeDriver(spec, car, i)
  if type(spec) == "function" then spec = spec(car, i) end
  if spec == nil then
    local ok, cls = pcall(drivers.load, "cruiser")
    spec = ok and cls or Steady
  end
  if drivers.isFile(spec) then return drivers.world(spec, car) end -- a world of its own
  if type(spec) == "string" then spec = drivers.load(spec) end
  if type(spec) == "table" and type(spec.update) ~= "function" and type(spec.new) == "function" then
    spec = spec.new {}
  end
  if type(spec) ~= "table" or type(spec.update) ~= "function" then
    pitwall._raise("race: the driver of " .. tostring(car) .. " must be a name, a driver class "
      .. "(with new) or a driver (with update), got " .. type(spec))
  end
  return spec
end

--- A session, not started yet: race.new{mode = "laps" | "timed" | "qualifying" | "practice", …}.
function race.new(options)
  options = options or {}
  if type(options) ~= "table" then
    pitwall._raise("race: the options are a table such as {laps = 5}, got " .. type(options))
  end
  local mode = options.mode or "laps"
  if not MODES[mode] then
    local names = { "laps", "timed", "qualifying", "practice" }
    local near = pitwall._nearest(tostring(mode), names)
    pitwall._raise("race.new: unknown mode '" .. tostring(mode) .. "'"
      .. (near and ("; did you mean " .. near .. "?") or "")
      .. " (the modes are laps, timed, qualifying, practice)")
  end
  pitwall._checkOptions("race." .. mode, options, race.options)
  if type(options.safety) == "table" then
    pitwall._checkOptions("race." .. mode .. ": safety", options.safety, { "distance", "speed" })
  end
  local seconds = options.seconds or (options.minutes and options.minutes * 60)
  if mode == "laps" and not options.laps then pitwall._raise("race.laps: give laps = N") end
  if mode == "timed" and not seconds then
    pitwall._raise("race.timed: give minutes = M (or seconds)")
  end
  if (mode == "qualifying" or mode == "practice") and not seconds and not options.laps then
    pitwall._raise("race." .. mode .. ": give minutes = M (or seconds, or laps)")
  end
  -- A ghost (sim.addGhost, run --ghost) is no entry: it stands at the line until the green
  -- light, then drives its lap again beside the race (docs/racing.md "Racing a ghost").
  local cars, ghosts = options.cars, {}
  if not cars then
    cars = {}
    for _, c in ipairs(pitwall.cars()) do
      if c.ghost then ghosts[#ghosts + 1] = c else cars[#cars + 1] = c end
    end
  end
  if #cars == 0 then pitwall._raise("race: no cars") end
  return setmetatable({
    mode = mode, options = options, cars = cars, ghosts = ghosts, seconds = seconds,
    laps = options.laps,
    period = options.period or 0.1, state = "new", entries = {}, order = {},
    finishers = 0, title = options.title or MODES[mode],
  }, Race)
end

-- The grid: a session (its results' order), or a list of cars or names; the rest after.
function Race:_gridOrder()
  local grid, out, seen = self.options.grid, {}, {}
  if type(grid) == "table" and grid.results then grid = grid:grid() end
  for _, g in ipairs(grid or {}) do
    local car = type(g) == "string" and pitwall.car(g) or g
    for _, c in ipairs(self.cars) do
      if c == car and not seen[c] then out[#out + 1], seen[c] = c, true end
    end
  end
  for _, c in ipairs(self.cars) do
    if not seen[c] then out[#out + 1], seen[c] = c, true end
  end
  return out
end

function Race:_map()
  local o = self.options
  if o.map then return o.map end
  -- a known layout (the simulator's, or --ble --track's) is the map unless a scan is asked for
  if not o.scan then
    local layout = track.fromLayout()
    if layout then
      if not pitwall.sim then
        pitwall.log("info", "race: the map is the layout " .. tostring(layout.name)
          .. " (--track; no scan lap)")
      end
      return layout
    end
  end
  if lastMap and lastMap.source == "scan" then
    pitwall.log("info", "race: the track map of the session before is used (no new scan lap)")
    return lastMap
  end
  -- A grid has 4 lanes: a fifth car stands in a second row behind the line, in the scan car's
  -- lane or another, and a scan lap (from the line round to the line) runs into it.
  if #self.cars > 4 then
    pitwall._raise(string.format("race: %d cars and a scan lap: a grid has 4 lanes, so cars 5 "
      .. "and on stand in a second row behind the line, where the scan car would run into them; "
      .. "race at most 4 cars with a scan lap, or leave scan out and give the layout the cars "
      .. "are on (--track LAYOUT; in the simulator its layout is the map)", #self.cars))
  end
  local scanOptions = type(o.scan) == "table" and o.scan or {}
  pitwall.log("info", "race: scan lap with " .. tostring(self.cars[1]))
  self.scanning = true -- (the view shows the phase)
  self:_viewStart()
  local ok, map, here = pcall(track.scan, self.cars[1], scanOptions)
  self.scanning = nil
  if not ok then error(map, 0) end
  -- where the scan left its car: known even on a track or at a speed without position updates
  self.scanHere = { car = self.cars[1], index = here }
  return map
end

-- Progress in laps: laps done + fraction of the lap (negative before the first crossing).
function Race:_progress(e, now)
  local d, i = e.loc:locate(now)
  if not d then return nil end
  local L = self.map:lapLength(0)
  if e.loc.index and i < e.loc.index and not e.loc.reverse then d = d + L end -- past the line
  local base = e.timer.start and e.timer.count or -1
  return base + d / L, d
end

-- The start: to the grid, then the lights (race_start.lua).
for name, fn in pairs(require "pitwall.race_start") do Race[name] = fn end
-- What the race view shows (race_view.lua).
for name, fn in pairs(require "pitwall.race_view") do Race[name] = fn end
-- Slow laps seen and contacts freed (race_marshal.lua).
for name, fn in pairs(require "pitwall.race_marshal") do Race[name] = fn end
-- Drivers in worlds of their own: out, back, what they read of the race (race_worlds.lua).
for name, fn in pairs(require "pitwall.race_worlds") do Race[name] = fn end
-- The results kept in the standings database when the session ends (race_standings.lua).
for name, fn in pairs(require "pitwall.race_standings") do Race[name] = fn end

function Race:_start(e)
  e.started = true
  drivers.call(e.driver, "start", e.car, e.ctx)
  self:_checkWorld(e)
end

function Race:_finish(e, t)
  if e.finished then return end
  self.finishers = self.finishers + 1
  e.finished, e.finishTime, e.finishRank = true, t, self.finishers
  e.progress = e.timer.count
  -- what the results say: the laps up to the flag (a finished car circles on at the cool-down
  -- speed while the others finish, and those laps are timed but not raced)
  e.final = { count = e.timer.count, best = e.timer.best, last = e.timer.last }
  if not self.leaderFinished or t < self.leaderFinished then self.leaderFinished = t end
  drivers.call(e.driver, "finish", e.car, e.ctx)
  -- A cool-down: on at a low speed (a parked car would block the lane at the line).
  if e.car.connected then pcall(e.car.setSpeed, e.car, self.options.cooldown or 300, 1000) end
  pitwall.log("debug", string.format("race: %s finished (%d laps)", tostring(e.car), e.timer.count))
  self:_emit("onFinish", e.car, e.finishRank, self)
end

function Race:_onLap(e, lap)
  self:_emit("onLap", e.car, lap, self)
  if e.finished then return end
  local mode, now = self.mode, lap.finish
  local timeUp = self.seconds and now >= self.green + self.seconds
  if mode == "laps" then
    local flag = self.leaderFinished and now >= self.leaderFinished
    if e.timer.count >= self.laps or flag then self:_finish(e, now) end
  elseif mode == "timed" then
    if self.leaderFinished then self:_finish(e, now)
    elseif timeUp then
      self:_standings(now)
      if self.order[1] == e then self:_finish(e, now) end
    end
  else -- practice, qualifying: each car on its own
    if (self.laps and e.timer.count >= self.laps) or timeUp then self:_finish(e, now) end
  end
end

-- The order of a practice or qualifying: by best lap (a time before none); the grid breaks ties.
local function byBestLap(a, b)
  local ab, bb = a.timer.best, b.timer.best
  if ab and bb and ab.time ~= bb.time then return ab.time < bb.time end
  if (ab == nil) ~= (bb == nil) then return ab ~= nil end
  return a.gridSlot < b.gridSlot
end

-- The order of a race: by laps (a finisher's laps are frozen at the line), then finishing time;
-- the grid breaks ties.
local function byProgress(a, b)
  local pa, pb = a.progress or -math.huge, b.progress or -math.huge
  -- (by the time each crossed the line: a lap recovered late is timed when it was driven)
  if a.finished and b.finished and pa == pb and a.finishTime ~= b.finishTime then
    return a.finishTime < b.finishTime
  end
  if a.finished and b.finished and pa == pb then return a.finishRank < b.finishRank end
  if pa ~= pb then return pa > pb end
  return a.gridSlot < b.gridSlot
end

-- Sorts self.order: finishers in finishing order, then by progress; the grid breaks ties.
function Race:_standings(now)
  for _, e in ipairs(self.order) do
    local p, d = self:_progress(e, now)
    if d then e.distance = d end
    if p and not e.finished then e.progress = p end
  end
  local timing = self.mode == "qualifying" or self.mode == "practice"
  table.sort(self.order, timing and byBestLap or byProgress)
end

-- The time `e` was at `progress` (laps), from its trace; nil before its trace begins.
local function traceTime(e, progress)
  local T, P = e.traceT, e.traceP
  local n = T and #T or 0
  if n == 0 or progress < P[1] then return nil end
  if progress >= P[n] then return T[n] end
  local lo, hi = 1, n -- P[lo] <= progress < P[hi]
  while hi - lo > 1 do
    local mid = (lo + hi) // 2
    if P[mid] <= progress then lo = mid else hi = mid end
  end
  return T[lo] + (T[hi] - T[lo]) * (progress - P[lo]) / (P[hi] - P[lo])
end

-- Gap to the leader: seconds and laps behind.
function Race:_gap(e, leader)
  if e == leader then return 0, 0 end
  if self.mode == "qualifying" or self.mode == "practice" then
    local a, b = e.timer.best, leader.timer.best
    return a and b and a.time - b.time or nil, 0
  end
  if e.finished and leader.finished then
    local lf, ef = leader.final or leader.timer, e.final or e.timer
    return e.finishTime - leader.finishTime, math.max(0, lf.count - ef.count)
  end
  if not (leader.progress and e.progress) then return nil, 0 end
  local behind = math.max(0, math.floor(leader.progress - e.progress))
  -- How long ago the leader was where this car is now: a car further back has a larger gap,
  -- always (the leader's progress only grows), so the table reads down in order.
  local at = traceTime(leader, e.progress)
  return at and math.max(0, (e.finishTime or pitwall.now()) - at), behind
end

-- Each car's progress over time while it races, for the gaps (two arrays of numbers: 16 bytes a
-- sample, ten samples a second).
function Race:_trace(now)
  for _, e in ipairs(self.order) do
    local p = e.progress
    if p and not e.finished then
      if not e.traceP then e.traceT, e.traceP = {}, {} end
      local P = e.traceP
      if #P == 0 or p > P[#P] then
        P[#P + 1] = p
        e.traceT[#e.traceT + 1] = now
      end
    end
  end
end

function Race:_safety(now)
  local s = self.options.safety
  if s == false then return end
  s = s or {}
  local range, speed = s.distance or 1000, s.speed or 300
  local L = self.map:lapLength(0)
  for _, e in ipairs(self.order) do e.limit = nil end
  for _, d in ipairs(self.order) do
    if d.lost and d.lostDistance then
      for _, e in ipairs(self.order) do
        if e ~= d and not e.lost and e.distance and e.loc.localized then
          local behind = (d.lostDistance - e.distance) % L
          if behind > 0 and behind <= range then
            e.limit = speed
            if e.limitedBy ~= d then
              -- a car whose link is down stands where it was lost, as far as anyone knows
              local why = d.car.connected and "left the track" or "stands, disconnected,"
              pitwall.log("warn", string.format("race: %s slowed to %d mm/s: %s %s %.0f mm ahead",
                tostring(e.car), speed, tostring(d.car), why, behind))
            end
            e.limitedBy = d
          end
        end
      end
    end
  end
  for _, e in ipairs(self.order) do if not e.limit then e.limitedBy = nil end end
end

function Race:_tick()
  local now = pitwall.now()
  local old = self._was or {} -- (each entry's place before this tick: one table a session)
  self._was = old
  for k, e in ipairs(self.order) do old[e] = e.position or k end
  for _, e in ipairs(self.order) do
    if e.lost and e.loc.localized then self:_found(e) end
  end
  self:_standings(now)
  self:_trace(now)
  for k, e in ipairs(self.order) do
    e.position = k
    if old[e] ~= k and self.ticks > 0 then self:_emit("onPositionChange", e.car, k, old[e], self) end
  end
  self.ticks = self.ticks + 1
  self:_safety(now)
  self:_marshal(now)
  local view
  for _, e in ipairs(self.order) do
    local car = e.car
    self:_checkWorld(e)
    if not e.started and now >= e.releaseAt and not e.out then self:_start(e) end
    if e.started and not e.finished and car.connected and not e.out then
      if e.ctx then e.ctx.limit, e.ctx.pieceLimits = e.limit, e.pieceLimits end
      view = self:_tellWorld(e, view)
      drivers.call(e.driver, "update", car, e.ctx)
      self:_checkWorld(e)
      self:_applyFloor(e, now)
      if e.limit and (car.targetSpeed or 0) > e.limit then pcall(car.setSpeed, car, e.limit, 2000) end
    elseif e.finished and car.connected and e.limit and (car.targetSpeed or 0) > e.limit then
      pcall(car.setSpeed, car, e.limit, 2000)
    end
  end
  -- time up in practice / qualifying: cars that are not moving have nothing left to do
  if self.seconds and now >= self.green + self.seconds and not self.timeUp then
    self.timeUp = now
    pitwall.log("info", "race: time is up")
  end
  if self.board and (not self.lastDraw or now - self.lastDraw >= (self.options.redraw or 0.25)) then
    self.lastDraw = now
    local status = self:_status(now)
    self.board.title = status ~= "" and self.title .. "   " .. status or self.title
    self.board:show(self:_rows())
  end
  -- Over when every car finished, or is away longer than reconnectTimeout (a link that drops,
  -- even every car's at once as when bluetoothd restarts, comes back: docs/bluetooth.md)
  local all = true
  local away = self.options.reconnectTimeout or 30
  for _, e in ipairs(self.order) do
    if e.car.connected then
      e.awaySince = nil
    else
      e.awaySince = e.awaySince or now
    end
    if not e.finished and not e.out and (e.car.connected or now - e.awaySince < away) then
      all = false
    end
  end
  local grace = self.options.finishTimeout or 60
  local since = self.leaderFinished or self.timeUp
  if all or (since and now - since > grace) then self.done = true end
end

-- What the board's title says: the leader's lap, the time left, the chequered flag.
function Race:_status(now)
  if self.leaderFinished then return "chequered flag" end
  local leader = self.order[1]
  if self.seconds then
    local left = self.green + self.seconds - now
    if left <= 0 then return self.mode == "timed" and "last lap" or "time is up: last laps" end
    return Board.time(left) .. " left"
  end
  if self.mode == "laps" then
    local lap = leader.timer.start and leader.timer.count + 1 or 1
    return string.format("lap %d/%d", math.min(lap, self.laps), self.laps)
  end
  return ""
end

-- A driver's name: its own `name`, else its class's.
local function driverName(driver)
  if type(driver) ~= "table" then return nil end
  local name = rawget(driver, "name")
  local class = getmetatable(driver)
  if name == nil and type(class) == "table" then
    name = rawget(class, "name")
    if name == nil and type(class.__index) == "table" then name = rawget(class.__index, "name") end
  end
  return type(name) == "string" and name or nil
end

-- Who drives a human's seat: a phone's player name, the gamepad's, …
local function playerOf(driver)
  local seat = type(driver) == "table" and rawget(driver, "seat")
  if type(seat) ~= "userdata" then return nil end
  local ok, player = pcall(function() return seat.player or seat.holder end)
  return ok and player or nil
end

-- "finished", "running" (racing, or the run ended first), "DNF" or "DNF (disconnected)".
function Race:_statusOf(e)
  if e.finished then return "finished" end
  if e.out then return "DNF" end -- its driver's world failed (row.reason says why)
  if self.state ~= "done" or self.cut then return "running" end
  return e.car.connected and "DNF" or "DNF (disconnected)"
end

-- Rows of the live board / results.
function Race:_rows()
  -- (in order as of now: a lap's event between two ticks may have changed it)
  if self.state == "racing" then self:_standings(pitwall.now()) end
  local rows, leader = {}, self.order[1]
  for k, e in ipairs(self.order) do
    local gap, behind = self:_gap(e, leader)
    local t = e.finished and e.final or e.timer
    local lastCross = e.finishTime or (t.last and t.last.finish)
    rows[k] = {
      position = k, car = e.car.name, number = e.car.number,
      driver = driverName(e.driver), player = playerOf(e.driver), status = self:_statusOf(e),
      laps = t.count,
      lap = e.finished and t.count or (t.start and math.min(t.count + 1, self.laps or math.huge) or 0),
      totalTime = lastCross and self.green and lastCross - self.green or nil,
      bestLap = t.best and t.best.time, lastLap = t.last and t.last.time,
      gap = gap, lapsBehind = behind,
      finished = e.finished or false, falseStart = e.falseStart or false,
      reason = not e.finished and e.out or nil,
    }
  end
  return rows
end

--- The result rows, in finishing order (qualifying, practice: best lap first).
function Race:results()
  local rows = self:_rows()
  local out = {}
  for k, r in ipairs(rows) do
    out[k] = {}
    for _, c in ipairs(race.columns) do out[k][c] = r[c] end
    out[k].gap, out[k].lapsBehind = r.gap, r.lapsBehind
  end
  return out
end

--- The cars in result order: a grid for the next session (grid = session works too).
function Race:grid()
  local out = {}
  for k, e in ipairs(self.order) do out[k] = e.car end
  return out
end

--- The entry of a car: {car, driver, ctx, loc, timer, position, progress, finished, …}.
function Race:entry(car)
  return self.entries[car]
end

--- Ends the session now (from a handler or another task); run() then stops every car.
function Race:abort()
  self.done = true
end

-- The entries: one per car, in grid order, each followed on the map.
function Race:_entries()
  for slot, car in ipairs(self:_gridOrder()) do
    local e = { car = car, loc = localize.follow(car, self.map), gridSlot = slot,
      started = false }
    if self.scanHere and self.scanHere.car == car then e.loc:assume(self.scanHere.index) end
    self.entries[car] = e
    self.order[slot] = e
  end
end

-- The driver of every car from this version's options, and its context. A car that is racing
-- already (a reload took the session up) gets its new driver through takeover, handed what the
-- driver before it handed over; a driver without takeover is started as at the green light.
function Race:_drivers()
  local field = {}
  for _, e in ipairs(self.order) do field[#field + 1] = { car = e.car, loc = e.loc } end
  local driverSpec = self.options.drivers
  for i, car in ipairs(self.cars) do
    local e = self.entries[car]
    local spec = driverSpec
    if type(driverSpec) == "table" and not driverSpec.update and not driverSpec.new then
      spec = driverSpec[car] or driverSpec[car.name] or driverSpec[i]
    end
    -- the command line's --driver CAR=FILE comes first (docs/drivers.md)
    spec = pitwall.driverFiles and pitwall.driverFiles[car.number] or spec
    e.driver = makeDriver(spec, car, i)
    e.ctx = drivers.context(car, self.map, field, { period = self.period })
    local h = e.handover
    e.handover = nil
    if h and e.started and not e.finished and self.phase == "racing" then
      if e.driver.takeover then
        local fine, err = xpcall(e.driver.takeover, pitwall._traceback, e.driver, car, e.ctx, h.state,
          h.name)
        if not fine then report("takeover of driver " .. tostring(e.driver.name or "?") .. " of "
          .. tostring(car), err) end
      else
        drivers.call(e.driver, "start", car, e.ctx)
      end
    end
  end
end

-- Lap timers (from the grid on) and what the director follows of each car.
function Race:_timing(adopted)
  for _, e in ipairs(self.order) do
    local onLap = function(_, lap) self:_onLap(e, lap) end
    if adopted and e.timer then
      e.timer = laps._adopt(e.timer, { onLap = onLap })
    else
      e.timer = laps.timer(e.car, self.map, { onLap = onLap })
    end
    e.unsubscribe = e.loc:subscribe {
      lost = function(_, t, why, index)
        if self.state == "racing" and e.distance then
          e.lost, e.lostDistance, e.lostWhy, e.lostAt = true, e.distance, why, t
          e.lostIndex = index
          e.lostSpeed = math.max(e.loc:speedAt(t), e.car.speed or 0)
        end
      end,
    }
    -- A car put back on the track (a status "on track" after it left) stands still: it is sent
    -- its last commanded speed again, so that its driver resumes.
    e.contactSub = pitwall.listen(e.car, "onCollision", function(_, ev) self:_contact(e, ev) end)
    e.statusSub = pitwall.listen(e.car, "onStatus", function(car, ev)
      if not ev.onTrack then e.offTrack = true
      elseif e.offTrack then
        e.offTrack = false
        if self.state == "racing" and e.started and (car.targetSpeed or 0) > 0 then
          pcall(car.setSpeed, car, car.targetSpeed, 1000)
        end
      end
    end)
  end
end

-- (A new version draws its board anew, below the reload's log lines: drawing over the last
-- version's board would overwrite them.)
function Race:_board()
  if self.options.board == false then return end
  self.board = Board.new {
    title = self.title,
    columns = {
      { key = "position", title = "POS", align = "right" },
      { key = "car", title = "CAR" },
      { key = "driver", title = "DRIVER",
        format = function(v, row) return row.player and row.player .. " (" .. (v or "?") .. ")" or v end },
      { key = "lap", title = "LAP", align = "right" },
      { key = "lastLap", title = "LAST", align = "right", format = Board.time },
      { key = "bestLap", title = "BEST", align = "right", format = Board.time },
      { key = "gap", title = "GAP", align = "right",
        format = function(v, row)
          if row.status ~= "finished" and row.status ~= "running" then return row.status end
          return Board.gap(v, row.lapsBehind)
        end },
    },
  }
end

-- The run ended while the session raced: the standings as they were, once.
function Race:_cut()
  self.phase, self.state, self.cut = "done", "done", true
  self:_standings(pitwall.now())
  self:_viewNow()
  pitwall.log("warn", string.format("race: the run ended before the %s did: the standings when "
    .. "it ended are its results", self.title))
  if self.board then
    self.board.title = self.title .. "   stopped"
    self.board:final(self:_rows())
  end
  local path = self.options.results
  if path == nil then path = pitwall.resultsFile end
  if path then self.resultsPath = pitwall.writeResults(self:results(), race.columns, path) end
  self:_keep()
end

-- Across reloads: what a session hands to the next version and how it takes it up
-- (race_reload.lua).
require("pitwall.race_reload")(Race, { modes = MODES, report = report })

local PHASES = { new = "the map", grid = "to the grid", lights = "the lights", racing = "racing",
  ending = "stopping the cars" }

local function listenKinds(cars)
  for _, car in ipairs(cars) do
    if not listening[car] then
      listening[car] = true
      lastKind[car] = lastKind[car] or "none"
      pitwall.listen(car, "onPosition", function() lastKind[car] = "position" end)
      pitwall.listen(car, "onTransition", function() lastKind[car] = "transition" end)
    end
  end
end

-- Sessions that were racing when the script was saved, taken up as this module loads (below) and
-- directed without drivers until the script's own call comes to them: run index → session.
local headless = {}
local runs = 0 -- run() calls in this version: the k-th takes up the k-th session carried

-- The script's call for a session taken up at load: this version's options, drivers and board;
-- then it waits for the session's end like any run.
function Race:_attach(new)
  self.options = new.options
  self:_applyOptions(new.options, new.mode, new.laps, new.seconds, new.title)
  self.penalty = new.options.falseStartPenalty or self.penalty
  pitwall.log("info", string.format("race: %s taken up by the new version (racing)", self.title))
  self:_drivers()
  self:_board()
  pitwall.waitUntil(function() return self.phase == "done" end, nil, self.period)
  return self
end

-- Racing until the session is done, then the end: every car stopped, the final table, the
-- results, onEnd. A session taken up at load runs this in a task of its own.
function Race:_race()
  local o = self.options
  if self.phase == "racing" then
    local ticker = pitwall.every(self.period, function()
      if self.done then return end
      local ok, err = xpcall(self._tick, pitwall._traceback, self)
      if not ok then report("race director", err) end
    end)
    pitwall.waitUntil(function() return self.done end, nil, self.period)
    ticker:cancel()
    self.state = "done"
    self.phase = "ending"
    self.endAt = pitwall.now() + 0.5
    self:_standings(pitwall.now())
    -- Every car brought to a stop.
    for _, e in ipairs(self.order) do
      if e.started and not e.finished then drivers.call(e.driver, "finish", e.car, e.ctx) end
      if e.car.connected then pcall(e.car.stop, e.car) end
    end
    for _, g in ipairs(self.ghosts or {}) do
      if g.connected then pcall(g.stop, g) end
    end
  end
  -- (car.speed is the last reported one: a stopped car reports nothing.) A version that took
  -- the session up here waits out what is left of the half second, no more.
  pitwall.sleep(math.max(0, (self.endAt or pitwall.now() + 0.5) - pitwall.now()))
  for _, e in ipairs(self.order) do
    e.unsubscribe(); e.timer:cancel(); e.statusSub:cancel(); e.contactSub:cancel()
  end
  self:_closeWorlds()
  if self.board then
    self.board.title = self.title .. "   results"
    self.board:final(self:_rows())
  end
  o = self.options -- (the script's call may have come meanwhile)
  local path = o.results
  if path == nil then path = pitwall.resultsFile end
  if path then self.resultsPath = pitwall.writeResults(self:results(), race.columns, path) end
  self:_keep()
  self.phase = "done"
  self:_viewNow()
  self:_emit("onEnd", self)
  return self
end

-- The session a reload interrupted at this call's place (the index-th run() of the version),
-- taken up where it was; true when it had already ended.
function Race:_takeUpCarried(index)
  local c = carried.sessions[index]
  if type(c) ~= "table" or type(c.order) ~= "table" or type(c.entries) ~= "table" then c = nil end
  carried.sessions[index] = nil
  if not c then return false end
  self:_takeUp(c)
  if self.phase == "done" then return true end
  pitwall.log("info", string.format("race: %s taken up by the new version (%s)", self.title,
    PHASES[self.phase] or self.phase))
  return false
end

-- What a session needs before the grid: the track's map and the entries (a new session), or the
-- trackers adopted (one taken up); the view told; the drivers made.
function Race:_prepare()
  self.phase = self.phase or "new"
  self.penalty = self.options.falseStartPenalty or self.penalty or 5
  if self.phase == "new" then
    self.scanning = nil -- (a scan a reload cut short starts again, or is not needed)
    self.map = self:_map()
    lastMap = self.map
    self:_viewStart()
    self:_viewMap()
    self:_entries()
    self.phase = "grid"
  else
    for _, e in ipairs(self.order) do e.loc = localize._adopt(e.loc) end
    self:_viewStart()
    self:_viewMap()
  end
  self:_drivers()
end

-- From the grid to the green light: the cars to their places, the lap timers, the board, the
-- lights (each skipped when the session is already past it).
function Race:_startSession()
  local o = self.options
  if self.phase == "grid" then
    if self.mode ~= "practice" then self:_toGrid() end
    self:_timing(false)
    self.phase = "lights"
  else
    self:_timing(true)
  end
  self:_board()
  if self.phase == "lights" then
    if self.mode ~= "practice" and o.lights ~= 0 then self:_lights() end
    self.state = "racing"
    self.green = pitwall.now()
    for _, g in ipairs(self.ghosts or {}) do -- (any speed above 0: it drives its lap's pace)
      if g.connected then pcall(g.setSpeed, g, 1000) end
    end
    for _, e in ipairs(self.order) do
      e.releaseAt = self.green + (e.falseStart and self.penalty or 0)
    end
    self.ticks = 0
    self.phase = "racing"
    self:_tick()
  end
end

--- Runs the session to its end inside a task; returns the session. A session that a reload of
--- the script interrupted is taken up where it was by the same call in the new version.
function Race:run()
  if not coroutine.isyieldable() then
    pitwall._raise("race: a session drives and waits: run it inside a task (the main chunk or "
      .. "pitwall.spawn), not in a handler")
  end
  self.lastKind = lastKind
  runs = runs + 1
  local index = runs
  listenKinds(self.cars)
  local h = headless[index]
  if h then
    headless[index] = nil
    return h:_attach(self)
  end
  sessions[index] = self
  if self:_takeUpCarried(index) then return self end
  self:_prepare()
  self:_startSession()
  return self:_race()
end

for mode in pairs(MODES) do
  race[mode] = function(options)
    options = options or {}
    if type(options) ~= "table" then
      pitwall._raise("race: the options are a table such as {laps = 5}, got " .. type(options))
    end
    options.mode = mode
    return race.new(options):run()
  end
end

-- A session that was racing when the script was saved goes on at once: its trackers and lap
-- timers follow the cars, laps and finishes are counted, and the cars keep their last commanded
-- speeds, until the script's own call — which may come later, after a pitwall.sleep — brings
-- this version's options and drivers (Race:_attach). A version that never makes the call
-- still sees the session to its end.
for index, c in pairs(carried.sessions) do
  if type(c) == "table" and type(c.order) == "table" and type(c.entries) == "table"
    and c.phase == "racing" and MODES[c.mode] then
    local h = setmetatable({ mode = c.mode, options = {}, cars = c.cars, lastKind = lastKind },
      Race)
    h:_takeUp(c)
    carried.sessions[index] = nil
    sessions[index], headless[index] = h, h
    listenKinds(h.cars)
    for _, e in ipairs(h.order) do e.loc = localize._adopt(e.loc) end
    h:_timing(true)
    h:_viewStart()
    h:_viewMap()
    pitwall.spawn(function() h:_race() end, "race " .. tostring(h.title))
  end
end

return race
