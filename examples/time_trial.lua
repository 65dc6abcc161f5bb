-- A time trial (qualifying): after a scan lap every car drives LAPS timed laps (default 3) on
-- its own, the best lap wins. The table is sorted by best lap; --results FILE keeps it.
--
--   build/pitwall run examples/time_trial.lua --fast --results trial.json
local race = require "pitwall.race"

local LAPS = tonumber(os.getenv("LAPS")) or 3
local trial = race.qualifying {
  laps = LAPS,
  scan = true,
  drivers = "cruiser",                 -- every car the same driver: the fastest car wins
  title = "Time trial",
}
local pole = trial:results()[1]
print(string.format("Fastest lap: %s, %s", pole.car, race.time(pole.bestLap)))
pitwall.stop()
