-- A grand prix: four cars with four different AI drivers, a scan lap to learn the track, five
-- lights, a race of LAPS laps (default 5) with a live leaderboard, and the results at the end.
--
--   build/pitwall run examples/grand_prix.lua                        -- simulator, real time
--   build/pitwall run examples/grand_prix.lua --fast --results gp.csv
--   build/pitwall run examples/grand_prix.lua --ble                  -- the same, real cars
--
-- On a terminal the leaderboard redraws in place; elsewhere only the final table is printed.
-- With --view the results stay on the view for SHOW seconds (default 30) before the run ends.
local race = require "pitwall.race"
local drivers = require "pitwall.drivers"

local LAPS = tonumber(os.getenv("LAPS")) or 5
-- A driver and its options for cars 1, 2, 3, 4, 5, … On the simulator's grid car 1 starts in
-- the inside lane (the shortest way round) and car 4 outside: the faster drivers start outside.
local lineup = {
  { "cruiser", { speed = 950 } },
  { "lanekeeper", { speed = 1000 } },
  { "follower", { speed = 1050 } },
  { "overtaker", { speed = 1100 } },
}

local function driverFor(car, i)
  local pick = lineup[(i - 1) % #lineup + 1]
  return drivers.load(pick[1]).new(pick[2])
end

local cars = {} -- (a ghost, from --ghost, races beside them: the race leaves it out)
for _, car in ipairs(pitwall.cars()) do
  if not car.ghost then cars[#cars + 1] = car end
end
print(string.format("Grand prix: %d cars, %d laps", #cars, LAPS))
local gp = race.laps {
  laps = LAPS,
  -- the first car drives a scan lap (also on real cars); a grid has 4 lanes, and with more cars
  -- the second row would be in its way: the simulator's layout is the map then
  scan = #cars <= 4,
  drivers = driverFor,
  title = string.format("Grand prix, %d laps", LAPS),
}
print(race.winner(gp) or "No winner: nobody finished")
if gp.resultsPath then print("Results written to " .. gp.resultsPath) end
if pitwall.view.active then -- the podium stays up on the view for a while
  local show = tonumber(os.getenv("SHOW")) or 30
  print(string.format("The results stay on the view for %d s (Ctrl-C ends sooner)", show))
  pitwall.sleep(show)
end
pitwall.stop()
