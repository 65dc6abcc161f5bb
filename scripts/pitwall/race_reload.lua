-- pitwall.race across reloads (docs/hot-reload.md "A race survives a reload"): what a session
-- hands to the next version of the script (Race:_carry) and how the next takes it up
-- (Race:_takeUp, Race:_applyOptions). Methods of a session; race.lua installs them.
local track = require "pitwall.track"
local Board = require "pitwall.board"

return function(Race, shared)
  local MODES, report = shared.modes, shared.report

  -- What the next version takes up (race.lua registers it with pitwall._carry): the session's data, each entry's data
  -- and what its driver hands over; not the options, drivers, handlers or board, which the next
  -- version brings.
  -- (_was: the places before a tick, keyed by this version's entries; the next tick makes it anew)
  local LEFT_BEHIND = { options = true, board = true, lastKind = true, _was = true }
  local LEFT_BEHIND_ENTRY = { driver = true, ctx = true, unsubscribe = true, statusSub = true,
    contactSub = true }
  function Race:_carry()
    local c = {}
    for k, v in pairs(self) do
      if not LEFT_BEHIND[k] then c[k] = v end
    end
    local copies = {}
    for _, e in ipairs(self.order) do
      local ce = {}
      for k, v in pairs(e) do
        if not LEFT_BEHIND_ENTRY[k] then ce[k] = v end
      end
      local d = e.driver
      if d then
        local h = { name = d.name }
        ce.handover = h
        if d.handover and e.started and not e.finished then
          -- the driver's own code: after the session's data is saved, in a call of its own
          pitwall._afterCarry(function()
            local fine, result = xpcall(d.handover, pitwall._traceback, d)
            if fine then h.state = result
            else report("handover of driver " .. tostring(d.name or "?") .. " of "
              .. tostring(e.car), result) end
          end)
        end
      end
      copies[e] = ce
    end
    c.entries, c.order = {}, {}
    for k, e in ipairs(self.order) do
      local ce = copies[e]
      if ce.limitedBy then ce.limitedBy = copies[ce.limitedBy] end
      c.order[k], c.entries[e.car] = ce, ce
    end
    return c
  end

  -- Takes up session `c` carried from the version before: its state as it was, this version's
  -- options where they may change mid-session (drivers, title, board, period, …); the mode and
  -- the cars cannot, the number of laps (or minutes) can.
  function Race:_takeUp(c)
    local newMode, newLaps, newSeconds, newTitle = self.mode, self.laps, self.seconds, self.title
    for k, v in pairs(c) do
      if k ~= "title" and k ~= "period" then self[k] = v end
    end
    if c.map then self.map = track._adopt(c.map) end
    self.title, self.period = c.title, self.period or c.period
    self:_applyOptions(self.options, newMode, newLaps, newSeconds, newTitle)
  end

  -- This version's options on a session taken up: the kind and the cars stay, the laps (minutes)
  -- may change, the title is the new one unless the kind was refused.
  function Race:_applyOptions(o, newMode, newLaps, newSeconds, newTitle)
    if newMode ~= self.mode then
      pitwall.log("warn", string.format("race: this version asks for a %s, but a %s is under way: "
        .. "a session cannot change its kind; it goes on as a %s", MODES[newMode]:lower(),
        MODES[self.mode]:lower(), MODES[self.mode]:lower()))
      self.title = o.title or self.title
    else
      self.title = newTitle or self.title
    end
    if o.cars and #o.cars ~= #self.cars then
      pitwall.log("warn", string.format("race: this version names %d car(s), the session under way "
        .. "has %d: the cars cannot change mid-session; it goes on with its own", #o.cars,
        #self.cars))
    end
    if self.phase == "done" or newMode ~= self.mode then return end
    if self.mode == "laps" and newLaps and newLaps ~= self.laps then
      local done = 0
      for _, e in ipairs(self.order) do done = math.max(done, e.timer and e.timer.count or 0) end
      if self.leaderFinished then
        pitwall.log("warn", string.format("race: laps = %d: the race is already over (%d laps); "
          .. "it stays so", newLaps, self.laps))
      else
        local old = self.laps
        self.laps = math.max(newLaps, done + 1)
        pitwall.log("info", string.format("race: %d laps instead of %d%s", self.laps, old,
          self.laps ~= newLaps and string.format(" (the leader has done %d already)", done) or ""))
      end
    elseif newSeconds and self.seconds and newSeconds ~= self.seconds and not self.timeUp
      and not self.leaderFinished then
      pitwall.log("info", string.format("race: %s instead of %s", Board.time(newSeconds),
        Board.time(self.seconds)))
      self.seconds = newSeconds
    end
  end
end
