-- The race as the race view shows it (docs/view.md "race"): a session reports its phase, its
-- table and every lap to pitwall.view ten times a second while it runs — to the view (--view)
-- and to the record (--record), which a replay shows as it was. Without either,
-- pitwall.view.active and pitwall.view.recording are false and nothing is built. Methods mixed
-- into Race (race.lua).
local View = {}

-- The publishers of this version's sessions (a timer is no data to carry across a reload: the
-- next version starts its own).
local publishers = setmetatable({}, { __mode = "k" })

-- (A new session that is not scanning is on its way to the grid: it has its map already.)
local VIEW_PHASES = { new = "grid", grid = "grid", lights = "lights", racing = "racing",
  ending = "ending", done = "done" }

--- The session as plain data for pitwall.view.race.
function View:_viewState()
  local phase = VIEW_PHASES[self.phase or "new"] or tostring(self.phase)
  if self.phase == "new" and self.scanning then phase = "scan" end
  local state = {
    title = self.title, mode = self.mode, phase = phase, laps = self.laps,
    seconds = self.seconds, green = self.green, rows = {}, lapTimes = {},
  }
  if phase == "lights" then state.light, state.lights = self.light or 0, self.options.lights or 5 end
  -- seconds a jump start is held after green (the phone says it during the lights and to whoever
  -- jumped)
  state.penalty = self.penalty
  if self.order and #self.order > 0 and self.order[1].timer then
    if self.green then
      local ok, status = pcall(self._status, self, pitwall.now())
      if ok then state.status = status end
    end
    local ok, rows = pcall(self._rows, self)
    if ok then
      for k, row in ipairs(rows) do
        local e = self.order[k]
        local car = e.car
        row.speed = car.speed
        row.lane = car.offset
        row.connected = car.connected
        local times = {}
        -- (the laps up to the flag: a finished car's cool-down laps are no race laps)
        local upTo = e.final and e.final.count or math.huge
        for i, lap in ipairs(e.timer.history or {}) do
          if i > upTo then break end
          times[i] = lap.time
        end
        state.lapTimes[tostring(car.number)] = times
        state.rows[k] = row
      end
    end
  end
  if phase == "done" then state.status = state.status or "results" end
  return state
end

--- Starts reporting this session to the view (once per session and version).
function View:_viewStart()
  local view = pitwall.view
  if not (view and (view.active or view.recording)) or publishers[self] then return end
  local failed = false
  local function publish()
    local ok, err = pcall(function() pitwall.view.race(self:_viewState()) end)
    if not ok and not failed then
      failed = true -- said once: the race goes on without its picture
      pitwall.log("warn", "race: the view cannot show " .. tostring(self.title) .. ": "
        .. tostring(err))
    end
  end
  publish()
  local timer
  timer = pitwall.every(0.1, function()
    publish()
    if self.phase == "done" then timer:cancel() end
  end)
  publishers[self] = { timer = timer, publish = publish }
end

--- Reports the session now (its end: a run may stop before the next tick).
function View:_viewNow()
  local p = publishers[self]
  if p then
    p.publish()
    if self.phase == "done" then p.timer:cancel() end
  end
end

--- The map the session races on, drawn by the view (a simulator's layout stays).
function View:_viewMap()
  if self.map and pitwall.view and pitwall.view.active then -- (a replay has its --track)
    pcall(pitwall.view.track, self.map)
  end
end

return View
