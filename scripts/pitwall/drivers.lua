-- pitwall.drivers: autonomous drivers ("strategies") and the context they drive with
-- (docs/racing.md "Drivers").
--
-- THE SHAPE. A driver module `scripts/pitwall/drivers/<name>.lua` returns a class table
--   { name = "<name>", new = function(options) → driver }
-- A driver is a table with methods, all optional except `update`:
--   driver:start(car, ctx)   once, when the car may drive (the green light);
--   driver:update(car, ctx)  every ctx.period s (default 0.1) while the car races; it commands
--                            the car itself (car:setSpeed(speed, accel), car:changeLane(offset))
--                            and sends no command that changes nothing (one frame per
--                            connection interval on a real car's link);
--   driver:finish(car, ctx)  when the car's race is over (the director stops the car anyway);
--   driver:waiting(car, ctx) every period while the start lights are on, for drivers that may
--                            move then (a human's throttle): a car that moves jumps the start.
-- ctx (drivers.context; a race director builds the same):
--   ctx.car, ctx.map (pitwall.track map), ctx.loc (this car's pitwall.localize tracker),
--   ctx.period (s), ctx.limit (speed cap, mm/s, nil = none: every driver respects it),
--   ctx.pieceLimits (map index → mm/s, or nil: curves the race saw the car thrown off; the
--   cruiser, and so every shipped driver, keeps to them),
--   ctx:ahead()          → nearest car ahead in driving order on the same map, any lane:
--                          {car, loc, gap = centre-line mm from us to it,
--                           time = gap / our speed in s (math.huge when stopped),
--                           lane = its offset (mm)} or nil
--   ctx:nearby(range)    → list of {car, loc, gap (signed mm, + ahead, − behind), lane}
--                          within range mm, sorted by gap
--   ctx:upcoming(dist)   → the map pieces the car covers in the next `dist` mm from where it is
--                          (the piece it is on first)
--
--   local drivers = require "pitwall.drivers"
--   local cls = drivers.load("cruiser")                  -- or a table taken as is
--   local ctx = drivers.context(car, map, field)         -- field: {{car =, loc =}, …}
--   local handle = drivers.run(car, cls.new{speed = 1200}, ctx)   -- a task; handle:stop()
local localize = require "pitwall.localize"

local drivers = {}

--- The driver class named `x` (pitwall.drivers.<x>), or `x` itself when it is a table.
function drivers.load(x)
  if type(x) == "table" then
    if type(x.new) ~= "function" then
      pitwall._raise("drivers.load: a driver class needs a function `new`")
    end
    return x
  end
  if type(x) ~= "string" then
    pitwall._raise("drivers.load: give a driver name (\"cruiser\") or a driver class table, got "
      .. type(x))
  end
  local module = "pitwall.drivers." .. x
  if not package.loaded[module] and not package.preload[module]
    and not package.searchpath(module, package.path) then
    -- not 22 lines of package.path: the drivers there are, and the one probably meant
    local names = drivers.names()
    local near = pitwall._nearest(x, names)
    pitwall._raise("drivers.load: no driver " .. x
      .. (near and ("; did you mean " .. near .. "? The") or "; the") .. " drivers are "
      .. table.concat(names, ", ") .. " (a driver of your own is a module "
      .. "pitwall.drivers.<name>: pitwall/drivers/<name>.lua beside your script)")
  end
  local ok, cls = pcall(require, module)
  if not ok then pitwall._rethrow("drivers.load: driver " .. x .. " does not load: ", cls) end
  return cls
end

--- The names of the drivers drivers.load finds (pitwall/drivers/*.lua along package.path),
--- sorted.
function drivers.names()
  return pitwall._modulesIn("pitwall.drivers")
end

--- Checks a driver's options: every key must be one of `known` (the driver's options and those
--- of the drivers inside it), else an error on the script's line naming `name` ("cruiser.new").
function drivers.checkOptions(name, options, known)
  return pitwall._checkOptionsOf(name, options, known)
end

--- The options of `options` that are in `known` (what a driver hands to the driver inside it).
function drivers.pick(options, known)
  local out = {}
  for _, k in ipairs(known) do out[k] = options[k] end
  return out
end

--- A list of the names in all the lists given, in order, each once.
function drivers.optionList(...)
  local out, seen = {}, {}
  for _, list in ipairs { ... } do
    for _, k in ipairs(list) do
      if not seen[k] then out[#out + 1], seen[k] = k, true end
    end
  end
  return out
end

-- Signed centre-line mm from a to b on a lap of length lap, in (−lap/2, lap/2].
local function signed(a, b, lap)
  local d = (b - a) % lap
  if d > lap / 2 then d = d - lap end
  return d
end

local Context = {}
Context.__index = Context
Context.__name = "driver context"

-- The field's entries as (car, loc), skipping our own car.
function Context:_each()
  local field, i = self.field, 0
  return function()
    while true do
      i = i + 1
      local f = field[i]
      if f == nil then return nil end
      local car, loc
      if type(f) == "table" and f.car then car, loc = f.car, f.loc else car = f end
      if car ~= self.car then
        loc = loc or localize.follow(car, self.map)
        if loc.map == self.map then return car, loc end
      end
    end
  end
end

function Context:ahead()
  local me = self.loc:distance()
  if not me then return nil end
  local lap = self.map:lapLength(0)
  local best
  for car, loc in self:_each() do
    local d = loc:distance()
    if d then
      local gap = (d - me) % lap
      if gap > 0 and (not best or gap < best.gap) then
        best = { car = car, loc = loc, gap = gap, lane = loc.offset }
      end
    end
  end
  if best then
    local v = self.loc.speed or 0
    best.time = v > 0 and best.gap / v or math.huge
  end
  return best
end

function Context:nearby(range)
  local out = {}
  local me = self.loc:distance()
  if not me then return out end
  local lap = self.map:lapLength(0)
  for car, loc in self:_each() do
    local d = loc:distance()
    if d then
      local gap = signed(me, d, lap)
      if math.abs(gap) <= range then
        out[#out + 1] = { car = car, loc = loc, gap = gap, lane = loc.offset }
      end
    end
  end
  table.sort(out, function(a, b) return a.gap < b.gap end)
  return out
end

function Context:upcoming(distance)
  local out = {}
  local d, i = self.loc:locate()
  if not d then return out end
  local map = self.map
  local p = map.pieces[i]
  out[1] = p
  local left = distance - (p.start + p.centre - d)
  local n = 1
  while left > 0 and n < #map.pieces do
    i = map:next(i)
    out[#out + 1] = map.pieces[i]
    left = left - map.pieces[i].centre
    n = n + 1
  end
  return out
end

--- The context a driver drives `car` with. `field` lists every racing car as {car =, loc =}
--- (loc: its pitwall.localize tracker on `map`) or as a bare car (its tracker is looked up).
--- The list is kept, not copied: cars added to it later are seen. options: period (0.1 s),
--- limit (mm/s).
function drivers.context(car, map, field, options)
  options = options or {}
  pitwall._checkOptionsOf("drivers.context", options, { "period", "limit" })
  for _, f in ipairs(field or {}) do -- follow bare cars from now on
    if not (type(f) == "table" and f.car) then localize.follow(f, map) end
  end
  return setmetatable({
    car = car, map = map, loc = localize.follow(car, map), field = field or {},
    period = options.period or 0.1, limit = options.limit,
  }, Context)
end

-- ---- helpers for drivers ----

--- The nearest car ahead whose offset is within `width` mm (default 45) of `lane`, within
--- `range` mm, from ctx:nearby: {car, loc, gap, lane} or nil. `skip(o)`, when given, leaves out
--- the cars it returns true for.
function drivers.aheadIn(ctx, lane, range, width, skip)
  width = width or 45
  for _, o in ipairs(ctx:nearby(range)) do
    if o.gap > 0 and o.lane and math.abs(o.lane - lane) < width and not (skip and skip(o)) then
      return o
    end
  end
  return nil
end

--- The speed cap of ctx applied to `v`.
function drivers.cap(ctx, v)
  if ctx.limit then return math.min(v, ctx.limit) end
  return v
end

--- A lane change is under way: car.laneChanging, unless the car's reported offset already is
--- within 5 mm of the target (the offset update that ends a change may have been lost).
function drivers.changing(car)
  return car.laneChanging and car.targetOffset ~= nil
    and math.abs((car.offset or 0) - car.targetOffset) > 5 or false
end

--- The car reported a position within the last `within` s (default 0.5) and a speed above 0:
--- it is moving (car.speed alone keeps its last value when a car is stopped by being put back).
function drivers.moving(car, within)
  local t = car.lastPositionTime
  return (car.speed or 0) > 0 and t ~= nil and pitwall.now() - t <= (within or 0.5)
end

--- Sends setSpeed only when it changes something: a speed at least `step` mm/s (default 10)
--- from the one last commanded (a stop always), or the same again when the car stands still
--- a second after it was asked to move (it was put back on the track, which stops it).
--- Returns true when it sent.
local sentAt = setmetatable({}, { __mode = "k" })
function drivers.setSpeed(car, speed, accel, step)
  speed = math.max(0, math.min(1500, math.floor(speed + 0.5)))
  local last, now = car.targetSpeed, pitwall.now()
  local stuck = speed > 0 and not drivers.moving(car, 1) and now - (sentAt[car] or -math.huge) > 1
  if not stuck and last and (math.abs(last - speed) < (step or 10) or last == speed)
    and not (speed == 0 and last ~= 0) then
    return false
  end
  car:setSpeed(speed, math.max(0, math.min(25000, math.floor(accel + 0.5))))
  sentAt[car] = now
  return true
end

local function report(where, message)
  if pitwall._reportError then
    pitwall._reportError(where, message)
  else
    pitwall.log("error", where .. ": " .. tostring(message))
  end
end

local function call(driver, method, car, ctx)
  -- (no driver: a session the library runs until the script's call gives it one)
  local fn = driver and driver[method]
  if not fn then return end
  local ok, err = xpcall(fn, pitwall._traceback, driver, car, ctx)
  if not ok then
    report(string.format("%s of driver %s of %s", method, tostring(driver.name or "?"),
      tostring(car)), err)
  end
end
drivers.call = call

-- ---- a driver in a world of its own ----

-- What a race director holds for a driver file in a Lua world of its own (docs/drivers.md): a
-- driver like any other, whose methods hand the call to the world with a copy of what it may
-- read. `world.failure` says why it is out (its car stopped); after a good save (a new world
-- version) a car that had started is started again in the new world.
local World = { __name = "driver world" }
World.__index = World

-- The world is called with the values driver_world.lua's call takes: the car, its limits, the
-- period, the race view (nil: the one it has), and the map (its first call, or after a save).
local function send(self, method, car, ctx)
  local w = self.world
  if w.failure then return end
  local limit, pieceLimits, period, race = nil, nil, nil, nil
  if ctx then limit, pieceLimits, period, race = ctx.limit, ctx.pieceLimits, ctx.period, ctx.race end
  local map
  if self.version ~= w.version then -- a new world (the first, or a save): the map, the race
    self.version, self.race = w.version, nil
    map = ctx and ctx.map
    if self.started and method ~= "start" and method ~= "finish" then
      if not w:call("start", car, limit, pieceLimits, period, race, false, map) then return end
      self.race, map = race, nil
    end
  end
  -- The race view the world has already (the same table: race_worlds' _tellWorld keeps it while
  -- nothing in it changes) is not copied again.
  local same = race ~= nil and race == self.race
  if method == "start" then self.started = true end
  if w:call(method, car, limit, pieceLimits, period, not same and race or nil, same, map) then
    self.race = race
  end
end

for _, method in ipairs { "start", "update", "finish", "waiting" } do
  World[method] = function(self, car, ctx) send(self, method, car, ctx) end
end

--- A driver for `car` from the Lua file `file`, run in a world of its own: the file returns a
--- driver class or a driver, as pitwall/drivers/*.lua do; the world commands `car` only, reads
--- no file, and its failure (an error, its budget, its memory cap) stops `car` and shows in
--- `driver.world.failure`. Limits: --driver-memory, --driver-budget.
function drivers.world(file, car)
  if type(file) ~= "string" then
    pitwall._raise("drivers.world: give the driver's file name, got " .. type(file))
  end
  local w = pitwall._driverWorld(file, car)
  local name = (file:match("([^/]+)$") or file):gsub("%.lua$", "")
  return setmetatable({ name = name, file = file, world = w, version = 0 }, World)
end

--- True for a driver given as a file (a string ending in .lua): drivers.world makes it.
function drivers.isFile(spec)
  return type(spec) == "string" and spec:match("%.lua$") ~= nil
end

--- Drives `car` with `driver` in a task of its own: start, then update every ctx.period s
--- until handle:stop() (which calls finish; it does not stop the car). An error in a method
--- is reported (pitwall.onError or the log) and the driver keeps being called.
function drivers.run(car, driver, ctx)
  if type(driver) ~= "table" or type(driver.update) ~= "function" then
    pitwall._raise("drivers.run: a driver is a table with an update method (make one with "
      .. "Class.new)")
  end
  local handle = { running = true, updates = 0 }
  pitwall.spawn(function()
    call(driver, "start", car, ctx)
    while handle.running do
      if car.connected then
        call(driver, "update", car, ctx)
        handle.updates = handle.updates + 1
      end
      pitwall.sleep(ctx.period)
    end
  end, "driver of " .. tostring(car))
  function handle:stop()
    if not self.running then return false end
    self.running = false
    call(driver, "finish", car, ctx)
    return true
  end
  return handle
end

return drivers
