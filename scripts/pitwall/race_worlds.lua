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

-- Whether `view` (the last one made) still says what the race says: the phase, the mode, the
-- laps, and of each car in order its place, laps, best lap, finish and whether it is out. Read in
-- place: a tick that changed nothing makes no table.
local function current(self, view)
  if view.phase ~= self.phase or view.mode ~= self.mode or view.laps ~= self.laps
    or #view.standings ~= #self.order then
    return false
  end
  local standings = view.standings
  for k, o in ipairs(self.order) do
    local s, t = standings[k], o.finished and o.final or o.timer
    if s.car ~= o.car or s.laps ~= t.count or s.bestLap ~= (t.best and t.best.time)
      or s.finished ~= (o.finished or false) or s.out ~= (o.out ~= nil) then
      return false
    end
  end
  return true
end

-- Before an update: a driver world's ctx.race is `view`, what it reads of the race (the phase
-- and every car's place, laps and best lap), looked at once a tick. While the race says what the
-- last view says (self._view), that table is kept: drivers.lua's send does not copy it into a
-- world again. Returns the view.
function Worlds:_tellWorld(e, view)
  if not worldOf(e) or not e.ctx then return view end
  if not view then
    view = self._view
    if not (view and current(self, view)) then
      local standings = {}
      for k, o in ipairs(self.order) do
        local t = o.finished and o.final or o.timer
        standings[k] = { car = o.car, position = k, laps = t.count,
          bestLap = t.best and t.best.time, finished = o.finished or false, out = o.out ~= nil }
      end
      view = { phase = self.phase, mode = self.mode, laps = self.laps, standings = standings }
      self._view = view
    end
  end
  e.ctx.race = view
  return view
end

return Worlds
