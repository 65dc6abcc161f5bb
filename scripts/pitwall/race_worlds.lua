-- Drivers in worlds of their own (drivers.world, docs/drivers.md) as the race director sees
-- them: a driver whose world failed puts its car out (DNF with the reason; its world stopped the
-- car as it failed), a good save brings it back while the race is on and the car has not
-- finished, and before each update the driver is told the race (ctx.race, a copy). Methods of a
-- session (pitwall.race); no state of their own.
local Worlds = {}

-- The driver world of an entry's driver, or nil (a driver of the director's own world, none).
local function worldOf(e)
  return type(e.driver) == "table" and rawget(e.driver, "world") or nil
end

function Worlds:_checkWorld(e)
  local w = worldOf(e)
  if not w then return end
  local why = w.failure
  if why and not e.out then
    e.out = why
    pitwall.log("info", "race: " .. tostring(e.car) .. " is out (DNF): its driver failed")
  elseif not why and e.out and not e.finished and not self.done then
    e.out = nil
    pitwall.log("info", "race: " .. tostring(e.car) .. " is back (driver " .. tostring(w.file)
      .. ", version " .. tostring(w.version) .. ")")
  end
end

-- The session ended: its driver worlds end too (they would follow every car until collected).
function Worlds:_closeWorlds()
  for _, e in ipairs(self.order) do
    local w = worldOf(e)
    if w then w:close() end
  end
end

-- What a view says of each car (its standings entries' fields).
local ENTRY = { "car", "position", "laps", "bestLap", "finished", "out" }

-- Two views that say the same.
local function same(a, b)
  if a.phase ~= b.phase or a.mode ~= b.mode or a.laps ~= b.laps
    or #a.standings ~= #b.standings then
    return false
  end
  for k, s in ipairs(a.standings) do
    local t = b.standings[k]
    for _, f in ipairs(ENTRY) do
      if s[f] ~= t[f] then return false end
    end
  end
  return true
end

-- Before an update: a driver world's ctx.race is `view`, what it reads of the race (the phase
-- and every car's place, laps and best lap), made once a tick. While it says the same as the last
-- one (self._view), that table is kept: drivers.lua's send does not copy it into a world again.
-- Returns the view.
function Worlds:_tellWorld(e, view)
  if not worldOf(e) or not e.ctx then return view end
  if not view then
    local standings = {}
    for k, o in ipairs(self.order) do
      local t = o.finished and o.final or o.timer
      standings[k] = { car = o.car, position = k, laps = t.count,
        bestLap = t.best and t.best.time, finished = o.finished or false, out = o.out ~= nil }
    end
    view = { phase = self.phase, mode = self.mode, laps = self.laps, standings = standings }
    if self._view and same(view, self._view) then view = self._view end
    self._view = view
  end
  e.ctx.race = view
  return view
end

return Worlds
