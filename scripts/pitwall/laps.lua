-- pitwall.laps: lap timing per car, from its localization on a track map (docs/racing.md
-- "Lap timing").
--
--   local laps = require "pitwall.laps"
--   local timer = laps.timer(car, map)
--   timer.onLap = function(car, lap) print(lap.number, lap.time) end
--   laps.onBestLap = function(car, lap) end   -- every timer's best laps
--   timer.count, timer.last, timer.best, timer.average, timer.history
--
-- A lap ends when the car goes from the last piece of the map (34) to the first (33) driving
-- forward, at the time of that transition (or, when its frame was lost, the time reckoned from
-- the speed). The first crossing starts lap 1. A crossing completes a lap only when the car was
-- followed, in order and forward, over at least `minCoverage` (75 %) of the lap's length since
-- the lap began; otherwise the lap starts again from this crossing and nothing is counted. So a
-- car that leaves the track and is put back where it left neither gains nor loses a lap; one
-- put back ahead, past most of the lap, gains nothing; one put back behind the line does not
-- count the line twice. Driving backwards over a piece takes it off the coverage again.
--
-- A lap is `clean` when the car stayed localized all through it (no delocalization, lift, or
-- loss of the map). Best and average count clean laps only.
local localize = require "pitwall.localize"

local laps = {}

--- Module-wide handlers, called for every timer after the timer's own:
--- laps.onLap = function(car, lap) end, laps.onBestLap = function(car, lap) end.
laps.onLap = nil
laps.onBestLap = nil

local Timer = {}
Timer.__index = Timer
Timer.__name = "lap timer" -- (how errors name it: "lap timer has no method …")

--- The default sectors of `map`: a list of the piece indices where each sector begins. The
--- first begins at the finish line; a new one begins on each straight that follows a curve,
--- except the straights that lead into the finish line (they end the last sector).
function laps.sectors(map)
  local pieces, n = map.pieces, #map.pieces
  local starts = { 1 }
  for i = 2, n do
    if pieces[i].type ~= "curve" and pieces[i - 1].type == "curve" then
      local j = i
      while j <= n and pieces[j].type ~= "curve" do j = j + 1 end
      if j <= n then starts[#starts + 1] = i end
    end
  end
  return starts
end

local function checkSectors(sectors, n)
  local problem
  if type(sectors) ~= "table" or sectors[1] ~= 1 then
    problem = "must be a list of piece indices beginning with 1 (the finish line)"
  else
    for k = 2, #sectors do
      local s = sectors[k]
      if math.type(s) ~= "integer" or s <= sectors[k - 1] or s > n then
        problem = string.format("entry %d (%s) must be an integer index greater than the one "
          .. "before it and at most %d (the map's pieces)", k, tostring(s), n)
        break
      end
    end
  end
  if problem then pitwall._raise("laps.timer: options.sectors " .. problem) end
end

--- A lap timer for `car` on `map`. options: sectors (a list of start indices, default
--- laps.sectors(map)), minCoverage (0..1, default 0.75), onLap, onBestLap (handlers, also
--- settable as timer.onLap / timer.onBestLap).
function laps.timer(car, map, options)
  options = options or {}
  pitwall._checkOptionsOf("laps.timer", options, { "sectors", "minCoverage", "onLap", "onBestLap" })
  local loc = localize.follow(car, map)
  local sectors = options.sectors or laps.sectors(map)
  checkSectors(sectors, #map.pieces)
  local self = setmetatable({
    car = car, map = map, localization = loc, sectors = sectors,
    minCoverage = options.minCoverage or 0.75,
    onLap = options.onLap, onBestLap = options.onBestLap,
    sectorAt = {},
  }, Timer)
  for k, i in ipairs(sectors) do self.sectorAt[i] = k end
  self:reset()
  self:_follow()
  return self
end

function Timer:_follow()
  self.unsubscribe = self.localization:subscribe {
    enter = function(_, i, from, t) self:_enter(i, from, t) end,
    lost = function() self.clean = false end,
  }
end

--- Takes up a timer carried from an earlier version of the script (docs/hot-reload.md): its
--- laps, times and the lap under way as they were, timing on. `options.onLap`,
--- `options.onBestLap`: its handlers in this version (handlers are not carried). The map must
--- have been taken up (track._adopt). Returns the timer.
function laps._adopt(data, options)
  if getmetatable(data) == Timer then return data end
  options = options or {}
  setmetatable(data, Timer)
  data.localization = localize._adopt(data.localization)
  data.onLap, data.onBestLap = options.onLap, options.onBestLap
  data:_follow()
  return data
end

--- Forgets every lap: the next finish crossing starts lap 1 (e.g. at a race start).
function Timer:reset()
  self.count, self.history = 0, {}
  self.last, self.best, self.average = nil, nil, nil
  self.start, self.marks, self.covered, self.clean = nil, {}, {}, false
end

--- Stops timing this car.
function Timer:cancel()
  if self.unsubscribe then self.unsubscribe() end
  self.unsubscribe = nil
end

function Timer:_enter(i, from, t)
  local map = self.map
  if from and map:next(from, 1) == i then
    if i == 1 then return self:_cross(t) end
    self.covered[i] = true
    local s = self.sectorAt[i]
    if s then self.marks[s] = t end
  elseif from and map:next(from, -1) == i then
    self.covered[from] = nil -- driven back over: not covered any more
  else
    self.covered[i] = true   -- found again after being lost
    self.clean = false
  end
end

local function call(timer, name, fn, lap)
  if not fn then return end
  local ok, err = xpcall(fn, pitwall._traceback, timer.car, lap)
  if ok then return end
  local where = name .. " handler of " .. tostring(timer.car)
  if pitwall._reportError then
    pitwall._reportError(where, err)
  else
    error(where .. ": " .. tostring(err), 0)
  end
end

function Timer:_cross(t)
  local lap
  if self.start then
    local covered = 0
    for i in pairs(self.covered) do covered = covered + self.map.pieces[i].centre end
    if covered >= self.minCoverage * self.map:lapLength(0) then
      lap = { number = self.count + 1, time = t - self.start, start = self.start, finish = t,
        clean = self.clean, sectors = {} }
      local n = #self.sectors
      for k = 1, n do
        local a, b = self.marks[k], k == n and t or self.marks[k + 1]
        lap.sectors[k] = a and b and b - a or false
      end
    end
  end
  -- The next lap starts here, counted or not.
  self.start, self.marks, self.covered, self.clean = t, { t }, { true }, true
  if not lap then return end

  self.count = lap.number
  self.history[#self.history + 1] = lap
  self.last = lap
  local newBest = false
  if lap.clean then
    local sum, clean = 0, 0
    for _, l in ipairs(self.history) do
      if l.clean then sum, clean = sum + l.time, clean + 1 end
    end
    self.average = sum / clean
    if not self.best or lap.time < self.best.time - 1e-6 then -- not float noise of a tie
      self.best, newBest = lap, true
    end
  end
  call(self, "onLap", self.onLap, lap)
  call(self, "onLap", laps.onLap, lap)
  if newBest then
    call(self, "onBestLap", self.onBestLap, lap)
    call(self, "onBestLap", laps.onBestLap, lap)
  end
end

return laps
