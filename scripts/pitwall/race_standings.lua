-- A session's results kept in the run's standings database when it ends (pitwall.keepResults,
-- docs/league.md "Standings"): who drove each car — the player of a human's seat, else the name
-- of its driver file, else the car — its place, laps and every lap's time, on the track by its
-- name (the map's, else the simulator's or --track's layout) or, scanned without one, its pieces. A session
-- the run cut short is kept as "stopped": its laps count, its places score nothing. Methods of a
-- session (pitwall.race); a session keeps its results once.
local Standings = {}

local KINDS = { laps = "race", timed = "race", qualifying = "qualifying", practice = "practice" }

-- "/home/class/alice.lua" → "alice"
local function stem(file)
  return (tostring(file):match("([^/]+)$") or tostring(file)):gsub("%.lua$", "")
end

function Standings:_keep()
  if self.kept or not pitwall.keepResults then return end
  self.kept = true
  local byNumber = {}
  for _, e in ipairs(self.order) do byNumber[e.car.number] = e end
  local entries = {}
  for _, r in ipairs(self:results()) do
    local e = byNumber[r.number]
    local world = e and type(e.driver) == "table" and rawget(e.driver, "world") or nil
    local times = {}
    if e and e.timer then
      for k, lap in ipairs(e.timer.history) do
        if k > (r.laps or 0) then break end
        times[k] = lap.time
      end
    end
    entries[#entries + 1] = {
      number = r.number, car = r.car,
      driver = r.player or (world and stem(world.file)) or r.car,
      file = world and world.file or nil,
      position = r.position, finished = r.finished, status = r.status, reason = r.reason,
      laps = r.laps, bestLap = r.bestLap, totalTime = r.totalTime, lapTimes = times,
    }
  end
  if #entries == 0 then return end
  local map, layout = self.map, pitwall.layout()
  local track = map and map.name or layout and layout.name or map and map:layout() or "unknown"
  local ok, kept, why = pcall(pitwall.keepResults, {
    kind = self.cut and "stopped" or pitwall.final and "final" or KINDS[self.mode] or "race",
    number = 1,
    laps = self.laps or 0, entries = entries, track = track,
    green = self.green }) -- (a personal best is a lap driven from the green light on)
  if not ok then
    pitwall.log("error", "race: the results were not kept in the standings: " .. tostring(kept))
  elseif why then -- (held, or kept beside the database: the run's end says what became of it)
    pitwall.log("warn", "race: " .. why)
  end
end

return Standings
