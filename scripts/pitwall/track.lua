-- pitwall.track: the map of a track, learnt by driving a scan lap (docs/racing.md).
--
--   local track = require "pitwall.track"
--   local map = track.scan(car)                -- inside a task: one slow lap in a fixed lane
--   map.pieces[i]                               -- {index, id, type, turn, centre, start, radius, angle}
--   map.pieces[i]:length(offset)                -- mm along the lane at `offset` (+ right)
--   map:lapLength(offset)                       -- mm of one lap in that lane
--
-- Pieces are in driving order starting with the piece after the finish line (33), so
-- `map.finishIndex` is always 1 and the last piece is 34 (on a track without them, from the
-- line: `map.hasStart` is false). A piece's `start` is the centre-line
-- distance from the finish line to its beginning. Offsets given to a map are in the map's
-- frame: right of the scan's driving direction (a car that drives reversed sees them mirrored).
--
-- The scan learns ids and order from position updates and transitions, types and lengths from
-- pitwall.piece(id), and which way each curve turns from the transition's wheel distances: in a
-- curve the outer wheel travels further (anki-overdrive.md, 0x29). A scan lap that lost a
-- transition (two pieces in one, a length that does not add up) is thrown away and the next
-- lap is scanned; a piece that got no position update takes its id from another good lap.
--
-- A track without the start/finish piece, or a car that sends few or no position updates, is
-- mapped as a loop (pitwall.track_loop): the lap closed by its curves' total turn, the pieces
-- the car saw no id on kept as pieces of unknown id, of the standard shape of their kind. Laps
-- are then counted at the beginning of the piece where the scan began, or at the line the
-- script names (`line = id`, map:withLine(index)).
local loop = require "pitwall.track_loop"

local track = {}

local Piece = {}
Piece.__index = Piece
Piece.__name = "track piece" -- (how errors name it: "track piece has no method …")

--- Length in mm along the lane at `offset` (mm right of the centre, map frame; default 0).
--- Straights are the same on every lane; a curve's outer lane is longer.
function Piece:length(offset)
  if not self.radius then return self.centre end
  local side = self.turn == "left" and 1 or -1
  return self.centre * (self.radius + side * (offset or 0)) / self.radius
end

function Piece:__tostring()
  return string.format("piece %d: %s %s%s", self.index, self.id or "id unknown", self.type,
    self.turn and (" " .. self.turn) or "")
end

local Map = {}
Map.__index = Map
Map.__name = "track map" -- (how errors name it: "track map has no method …")

-- Lap lengths already summed, by map (weak: a map no one holds goes) and offset, while the map
-- has as many pieces as when they were summed (drivers ask every update, the race every tick):
-- the first 8 offsets asked, the lanes (a car's own offset changes all the time: not kept).
local lapLengths = setmetatable({}, { __mode = "k" })
local KEPT_OFFSETS = 8

--- Length in mm of one lap along the lane at `offset` (default 0: the centre line).
function Map:lapLength(offset)
  offset = offset or 0
  local known = lapLengths[self]
  if not known or known.n ~= #self.pieces then
    known = { n = #self.pieces, count = 0, lengths = {} }
    lapLengths[self] = known
  end
  local total = known.lengths[offset]
  if total then return total end
  total = 0
  for _, p in ipairs(self.pieces) do total = total + p:length(offset) end
  if known.count < KEPT_OFFSETS and offset == offset then -- (NaN is no key)
    known.lengths[offset], known.count = total, known.count + 1
  end
  return total
end

--- The index after `i` driving forward (dir 1, default) or reversed (dir -1), wrapping around.
function Map:next(i, dir)
  local n = #self.pieces
  return (i - 1 + (dir or 1)) % n + 1
end

--- The indices of every piece with road piece id `id`, in order.
function Map:find(id)
  local out = {}
  for i, p in ipairs(self.pieces) do
    if p.id == id then out[#out + 1] = i end
  end
  return out
end

--- Whether a car reporting road piece id `id` can be on piece `i`: the piece has that id, or
--- its id is unknown (a scan that saw no position update on it) and it is of the id's kind.
function Map:fits(i, id)
  local p = self.pieces[i]
  if p.id ~= nil then return p.id == id end
  local spec = pitwall.piece(id)
  return spec ~= nil and spec.type == p.type
end

--- The indices of every piece a car reporting `id` can be on (Map:fits), in order.
function Map:candidates(id)
  local out = {}
  for i in ipairs(self.pieces) do
    if self:fits(i, id) then out[#out + 1] = i end
  end
  return out
end

--- The same track with the finish line at the beginning of piece `index`: a new map whose
--- piece 1 is this one's piece `index` (laps are counted where the last piece meets the first).
function Map:withLine(index)
  local n = #self.pieces
  if math.type(index) ~= "integer" or index < 1 or index > n then
    pitwall._raise(string.format("map:withLine: %s is not a piece index of this map (1..%d)",
      tostring(index), n))
  end
  local fields = {}
  for k, v in pairs(self) do
    if k ~= "pieces" then fields[k] = v end
  end
  local rotated = setmetatable(fields, Map)
  rotated.pieces, rotated.finishIndex = {}, 1
  local start = 0
  for k = 1, n do
    local p = {}
    for key, v in pairs(self.pieces[(index - 2 + k) % n + 1]) do p[key] = v end
    p.index, p.start = k, start
    start = start + p.centre
    rotated.pieces[k] = setmetatable(p, Piece)
  end
  return rotated
end

local letters = { straight = "S", curve = "?", intersection = "X" }

-- A number as text that reads back as exactly that number (a layout must close as it did).
local function exact(x)
  local s = string.format("%.15g", x)
  if tonumber(s) ~= x then s = string.format("%.17g", x) end
  return s
end

--- The map as simulator layout text ("start S L L S S L L"); with `ids`, "S:36 L:17 …" and a
--- custom piece's shape ("S:60,len=300").
function Map:layout(ids)
  local n = #self.pieces
  -- 34 (last) and 33 (first) are the start pair; the rest in order. A loop without them (a
  -- track with no start piece, or its line elsewhere) is every piece in order; a piece whose id
  -- is unknown has none.
  local paired = self.pieces[1].id == 33 and self.pieces[n].id == 34
  local words, from, to = { "start" }, 2, n - 1
  if not paired then words, from, to = {}, 1, n end
  for i = from, to do
    local p = self.pieces[i]
    local letter = p.type == "curve" and (p.turn == "left" and "L" or "R") or letters[p.type]
      or ("?" .. p.type)
    local word = (ids and p.id) and (letter .. ":" .. p.id) or letter
    -- a custom piece's shape, as a layout gives it (docs/tracks.md)
    if ids and p.custom then
      if p.radius then
        word = word .. ",r=" .. exact(p.radius) .. ",deg=" .. exact(p.angle)
      else
        word = word .. ",len=" .. exact(p.centre)
      end
    end
    words[#words + 1] = word
  end
  return table.concat(words, " ")
end

function Map:__tostring()
  return string.format("track map: %s (%d pieces, %.0f mm)", self:layout(), #self.pieces,
    self:lapLength(0))
end

-- The standard shape of a kind of piece, for a piece whose id a scan never saw.
local SHAPE_OF = { curve = 17, straight = 36 }

-- Builds a map from {id=, turn=, measured=} entries in driving order, 33 first, 34 last (or,
-- for a loop, from the line; an entry without id has `type`, and the standard shape of it).
local function build(entries, fields)
  local map = setmetatable(fields or {}, Map)
  map.pieces, map.finishIndex = {}, 1
  local start = 0
  for i, e in ipairs(entries) do
    local spec = pitwall.piece(e.id or SHAPE_OF[e.type] or -1)
    if e.id == nil and spec then
      spec = { type = e.type, length = spec.length, radius = spec.radius,
        angle = e.angle or spec.angle }
    end
    local p = setmetatable({
      index = i,
      id = e.id,
      type = spec and spec.type or "unknown",
      -- Unknown pieces (specials, jumps): their measured length, the same on every lane.
      centre = spec and spec.length or e.measured or 0,
      radius = spec and spec.radius,
      angle = spec and spec.angle,
      custom = spec and spec.custom or nil,
      start = start,
    }, Piece)
    if p.radius then p.turn = e.turn end
    start = start + p.centre
    map.pieces[i] = p
  end
  return map
end

-- The map of a layout table (sim.track(), pitwall.layout()): its pieces from the line on.
local function fromTable(t, source)
  local n = #t.pieces
  local entries = {}
  for k = 0, n - 1 do
    local p = t.pieces[(t.finishIndex - 1 + k) % n + 1]
    entries[#entries + 1] = { id = p.id, turn = p.turn > 0 and "left" or p.turn < 0 and "right" or nil,
      measured = p.length }
  end
  -- a track without the start piece: its laps from the beginning of its first piece, as the
  -- simulator counts them
  local hasStart = entries[1].id == 33 and entries[n].id == 34
  return build(entries, { name = t.name, source = source, hasStart = hasStart })
end

--- The map of the simulator's track, without driving (simulator runs only: a test's or a
--- script's shortcut; on real cars use track.scan).
function track.fromSim()
  local sim = require "pitwall.sim"
  return fromTable(sim.track(), "sim")
end

--- The map of the layout the cars are on, without driving: the simulator's track, or on real
--- cars the layout given with --track (the pieces as built: nominal lengths). nil when no layout
--- is known (real cars without --track: scan the track).
function track.fromLayout()
  local t = pitwall.layout()
  if not t then return nil end
  return fromTable(t, pitwall.sim and "sim" or "layout")
end

-- ---- the scan lap ----

-- A scan segment: what the car saw between two transitions.
local function newSegment(time, byTransition)
  return { ids = {}, idCount = 0, t0 = time, byTransition = byTransition, reckoned = 0 }
end

local segmentId, NO_POSITION = loop.segmentId, loop.NO_POSITION

-- Why a closed segment cannot be used, or nil when it is good. NO_POSITION is a lesser
-- problem: the piece is there, only its id is missing (another lap may have it).
local function segmentProblem(seg)
  if not seg.byTransition then return "it did not start at a transition" end
  if seg.idCount > 1 then return "two pieces in one (a lost transition)" end
  local wheels = (seg.left + seg.right) * 5 -- mean of both wheels, cm → mm
  -- A lost transition between two pieces with the same id: twice the distance driven (not
  -- known while the car's speed is not: no position update yet since the scan set it).
  if not seg.blind and math.abs(seg.reckoned - wheels) > math.max(0.35 * wheels, 80) then
    return string.format("driven %.0f mm but the wheels say %.0f mm", seg.reckoned, wheels)
  end
  if seg.idCount == 0 then return NO_POSITION end
  local spec = pitwall.piece(segmentId(seg))
  if spec and spec.type == "curve" and seg.left == seg.right then
    return "a curve with equal wheel distances"
  end
  return nil
end

-- The piece ids of a clean lap in the closed segments `segs`, and that lap's segments; nil
-- when there is none yet. A lap runs from a finish crossing to the next; a crossing is the
-- transition that ends a good segment on 34 or begins a good one on 33 (the two always follow
-- each other). A lap counts when none of its transitions was lost; a piece without a position
-- update takes its id from another such lap with as many pieces.
local function findLap(segs)
  local function good(i, id)
    return segs[i] and not segs[i].problem and segmentId(segs[i]) == id
  end
  local runs, from = {}, nil
  for i = 2, #segs + 1 do
    if good(i - 1, 34) or good(i, 33) then -- segment i begins at the finish line
      if from then runs[#runs + 1] = table.move(segs, from, i - 1, 1, {}) end
      from = i
    end
  end
  local usable = {}
  for _, run in ipairs(runs) do
    local ok = true
    for _, s in ipairs(run) do
      if s.problem and s.problem ~= NO_POSITION then ok = false break end
    end
    if ok then usable[#usable + 1] = run end
  end
  for r = #usable, 1, -1 do
    local run, ids, missing = usable[r], {}, false
    for k, s in ipairs(run) do
      ids[k] = segmentId(s) or (k == 1 and 33) or nil
      if not ids[k] then missing = true end
    end
    for _, other in ipairs(usable) do
      if not missing then break end
      if other ~= run and #other == #run then
        local agree = true
        for k, s in ipairs(other) do
          local id = segmentId(s)
          if id and ids[k] and id ~= ids[k] then agree = false break end
        end
        if agree then
          missing = false
          for k, s in ipairs(other) do
            ids[k] = ids[k] or segmentId(s)
            if not ids[k] then missing = true end
          end
        end
      end
    end
    if not missing then return ids, run end
  end
  return nil
end

-- Scans under way, for the next version of the script (a reload during a scan lap goes on with
-- it instead of starting another).
local scanning = {}
local carriedScans -- the scans an earlier version had under way, taken up one by one

pitwall._carry("track", function()
  local out = {}
  for st in pairs(scanning) do out[#out + 1] = st end
  if carriedScans == nil then -- this version never scanned: the scans carried to it go on
    local c = pitwall._takeCarried("track")
    carriedScans = type(c) == "table" and type(c.scans) == "table" and c.scans or {}
  end
  for _, st in ipairs(carriedScans) do out[#out + 1] = st end
  return { scans = out }
end)

local function takeScan(car)
  if carriedScans == nil then
    local c = pitwall._takeCarried("track")
    carriedScans = type(c) == "table" and type(c.scans) == "table" and c.scans or {}
  end
  for k, st in ipairs(carriedScans) do
    if type(st) == "table" and st.car == car and type(st.segs) == "table" then
      table.remove(carriedScans, k)
      return st
    end
  end
  return nil
end

--- Takes up a map carried from an earlier version of the script (its methods stay behind, so
--- they are given back here). Returns the map.
function track._adopt(map)
  if getmetatable(map) == Map then return map end
  setmetatable(map, Map)
  for _, p in ipairs(map.pieces) do setmetatable(p, Piece) end
  return map
end

-- track.scan (drive true) and track.learn (drive false: the car is not commanded).
local function scan(car, options, drive)
  local name = drive and "track.scan" or "track.learn"
  options = options or {}
  if not coroutine.isyieldable() then
    pitwall._raise(name .. (drive and " drives a lap" or " watches the car's laps")
      .. " and waits for it: call it inside a task (the script's main chunk or pitwall.spawn), "
      .. "not in a handler or timer")
  end
  if type(options) ~= "table" then
    pitwall._raise(name .. ": options must be a table such as "
      .. (drive and "{speed = 350}" or "{timeout = 60}") .. ", got " .. type(options))
  end
  pitwall._checkOptions(name, options, drive and { "speed", "offset", "timeout", "stop", "line" }
    or { "timeout", "line" })
  local speed = options.speed or 350
  local timeout = options.timeout or 120
  if type(speed) ~= "number" or speed < 100 or speed > 1000 then
    pitwall._raise("track.scan: speed " .. tostring(speed) .. " mm/s is outside 100..1000 (a scan "
      .. "drives slowly so that no position update is missed; 300–400 is a good choice)")
  end
  if not car.connected then
    pitwall._raise(name .. ": " .. tostring(car) .. " is not connected")
  end

  -- The scan's state is one table, so that a reload of the script takes it up where it was
  -- (pitwall._carry below): the new version's track.scan of the same car goes on with it.
  local now = pitwall.now()
  local st = takeScan(car) or { car = car, speed = speed, phase = "start", segs = {}, cur = nil,
    -- (its speed unknown until it reports one: a scan sets it now, a car watched may be
    -- driving at any speed)
    lastTime = now, lastSpeed = nil, reversed = false, delocalized = false,
    uturns = 0, deadline = now + timeout }
  speed = st.speed
  scanning[st] = true
  local function reckon(t)
    if st.cur and st.lastSpeed then
      st.cur.reckoned = st.cur.reckoned + st.lastSpeed * (t - st.lastTime)
    elseif st.cur then
      st.cur.blind = true
    end
    st.lastTime = t
  end
  local subs = {
    pitwall.listen(car, "onPosition", function(_, ev)
      st.finding = nil
      reckon(ev.time)
      st.lastSpeed = ev.speed
      st.reversed = ev.reverse
      if st.reversed then
        -- Driving backwards the pieces come the other way round: nothing of it is kept.
        st.segs, st.cur = {}, nil
        return
      end
      local cur = st.cur or newSegment(ev.time, false)
      st.cur = cur
      if not cur.ids[ev.piece] then
        cur.ids[ev.piece] = true
        cur.idCount = cur.idCount + 1
      end
    end),
    pitwall.listen(car, "onTransition", function(_, ev)
      reckon(ev.time)
      if st.reversed then return end
      local cur = st.cur
      if cur then
        cur.left, cur.right, cur.offset = ev.leftWheel, ev.rightWheel, ev.offset
        cur.problem = segmentProblem(cur)
        st.segs[#st.segs + 1] = cur
      end
      st.cur = newSegment(ev.time, true)
    end),
    pitwall.listen(car, "onDelocalized", function()
      if not st.finding then st.delocalized = true end
    end),
    -- A car stops when its link drops (a real car does, and so does the simulator's): the scan
    -- goes on where it was once the car is back, and a driving scan sets its speed again (a car
    -- that rebooted comes back delocalized: it finds the track as it drives).
    pitwall.listen(car, "onDisconnect", function()
      reckon(pitwall.now())
      st.lastSpeed = 0
    end),
    pitwall.listen(car, "onConnect", function()
      st.finding = true -- until its first position: a car that rebooted is not on the map yet
      if drive and st.phase == "lap" then pcall(car.setSpeed, car, speed, 1000) end
    end),
  }
  local function cancel()
    for _, s in ipairs(subs) do s:cancel() end
    scanning[st] = nil
  end

  local ok, result, here = pcall(function()
    local function waitFor(cond, what)
      local left = st.deadline - pitwall.now()
      if left <= 0 or not pitwall.waitUntil(cond, left) then
        local named = 0
        for _, s in ipairs(st.segs) do named = named + s.idCount end
        pitwall._raise(string.format("%s: %s within %g s with %s (%d pieces crossed%s); "
          .. "give a longer timeout, or check that the car drives round a closed track", name, what,
          timeout, tostring(car), #st.segs, named == 0 and #st.segs > 0
            and ", not one position update among them" or ""))
      end
    end
    if st.phase == "start" and not drive then
      st.phase = "lap"
    elseif st.phase == "start" then
      car:setSpeed(speed, 1000)
      if options.offset then
        waitFor(function() return (car.speed or 0) > 0 end, "the car did not start moving")
        car:changeLane(options.offset)
        -- Its offset update may be lost: the offsets in position updates tell as well.
        waitFor(function()
          return not car.laneChanging or math.abs((car.offset or 0) - options.offset) < 2
        end, "the lane change did not finish")
        st.segs, st.cur = {}, nil -- what was seen while changing lanes does not count
      end
      st.phase = "lap"
    else
      pitwall.log("info", string.format("%s: %s goes on with the scan an earlier version "
        .. "began (%d pieces crossed)", name, tostring(car), #st.segs))
    end
    local ids, run, lap
    waitFor(function()
      if st.delocalized then
        pitwall._raise(name .. ": " .. tostring(car) .. " left the track during the scan; put it "
          .. "back and scan again, slower")
      end
      if drive and st.reversed and (not st.turnedAt or pitwall.now() - st.turnedAt > 1) then
        -- It drives reversed: turn it round (once more if that did not take within 1 s).
        st.uturns = st.uturns + 1
        if st.uturns > 3 then
          pitwall._raise("track.scan: " .. tostring(car) .. " keeps driving reversed after 3 U-turns")
        end
        car:uturn()
        st.turnedAt = pitwall.now()
      end
      ids, run = findLap(st.segs)
      if ids then return true end
      -- no finish-to-finish lap yet: a loop closed by its turn (a track without the start
      -- piece; a car that sends few or no position updates). A scan whose car sends position
      -- updates at all drives up to five passes for the ids of pieces that had none; learning
      -- takes what came (a record ends).
      lap = loop.close(st.segs)
      return lap ~= nil and (not drive or lap.unknown == 0 or lap.named == 0
        or lap.seen >= 5 * lap.period)
    end, "no complete lap (neither one from finish line to finish line nor a loop whose curves "
      .. "turn 360°)")

    local entries, turns, offsets, first = {}, 0, 0, nil
    local fields = { source = "scan", scanSpeed = speed, scannedBy = car.name }
    if ids then
      for k, s in ipairs(run) do
        local e = { id = ids[k], measured = (s.left + s.right) * 5 }
        local spec = pitwall.piece(e.id)
        if spec and spec.type == "curve" then
          -- The outer wheel travels further: the right wheel in a left curve.
          e.turn = s.right > s.left and "left" or "right"
          turns = turns + (e.turn == "left" and 1 or -1) * spec.angle
        end
        offsets = offsets + s.offset
        entries[#entries + 1] = e
      end
      for k, s in ipairs(st.segs) do
        if s == run[1] then first = k break end
      end
      fields.scanOffset = offsets / #entries
    else
      entries, first = lap.pieces, lap.first
      for k = first, first + lap.period - 1 do offsets = offsets + st.segs[k].offset end
      fields.scanOffset = offsets / lap.period
    end
    local map = build(entries, fields)
    -- a track without the start piece counts laps where the scan began, or at the script's line
    map.hasStart = map:find(33)[1] ~= nil
    if math.abs((turns + 180) % 360 - 180) > 0.5 then
      pitwall.log("warn", string.format("%s: the curves turn %g° in all; a closed track "
        .. "turns a multiple of 360°: a curve's direction may be wrong", name, turns))
    end
    -- the piece the car is on now (its open segment comes after the closed ones)
    local here = (#st.segs - first + 1) % #map.pieces + 1
    -- the line: the script's, else the finish line (33 first), else where the scan began
    local line = 1
    if options.line ~= nil then
      line = map:find(options.line)[1]
      if not line then
        local seen = {}
        for _, p in ipairs(map.pieces) do
          if p.id then seen[#seen + 1] = tostring(p.id) end
        end
        pitwall._raise(string.format("%s: line = %s: no piece of the map has that id "
          .. "(ids seen: %s); name one of them, or leave line out to count laps at the "
          .. "finish line, or where the scan began on a track without one", name, tostring(options.line),
          #seen > 0 and table.concat(seen, ", ") or "none"))
      end
    elseif not ids then
      line = map:find(33)[1] or 1
    end
    if line ~= 1 then
      map = map:withLine(line)
      here = (here - line) % #map.pieces + 1
    end
    if drive and options.stop ~= false then car:stop() end
    -- the race view draws what was learnt (a simulator's layout stays: pitwall.view.track)
    if pitwall.view and pitwall.view.active then pcall(pitwall.view.track, map) end
    return map, here
  end)
  cancel()
  -- (its errors name the script's line already: pitwall._raise, the bindings)
  if not ok then
    -- a scan that failed leaves no car driving at the scan speed (unless told to keep it going)
    if drive and options.stop ~= false and car.connected then pcall(car.stop, car) end
    error(result, 0)
  end
  return result, here
end

--- Drives `car` one lap in a fixed lane and returns the map, and the index of the map piece
--- the car is on at its end (inside a task only).
--- options: speed (mm/s, default 350), offset (mm: change to this lane first; default: stay),
--- timeout (s, default 120), stop (default true: stop the car once the map is complete, and
--- when the scan fails; false leaves it driving at the scan speed), line (a piece id: laps are
--- counted at the beginning of the first piece with it; default the finish line, and where the
--- scan began on a track without one).
function track.scan(car, options)
  return scan(car, options, true)
end

--- The map of the track `car` drives, learnt from its events as track.scan learns it but
--- without commanding the car (a car someone else drives; a record replayed with --script),
--- and the index of the map piece it is on by then (inside a task only).
--- options: timeout (s, default 120), line (as track.scan's).
function track.learn(car, options)
  return scan(car, options, false)
end

return track
