-- A short race for mqtt_fleet_test.sh: every car of the run (remote cars bridged by another
-- pitwall, and local ones) races LAPS laps (default 1) on the simulator's map of the oval, the
-- layout the bridge's cars drive on too (no scan lap: quicker, and no timing of frames that
-- crossed a broker). Prints one line per car and the winner.
local race = require "pitwall.race"

local cars = pitwall.cars()
local names = {}
for i, car in ipairs(cars) do names[i] = tostring(car) end
print(string.format("Race: %d cars: %s", #cars, table.concat(names, ", ")))
local r = race.laps {
  laps = tonumber(os.getenv("LAPS")) or 1,
  drivers = function(_, i) return race.Steady.new { speed = 850 + 50 * i, accel = 2000 } end,
}
for _, x in ipairs(r:results()) do
  print(string.format("result %d %s laps=%d finished=%s time=%.2f", x.position, x.car, x.laps,
    tostring(x.finished), x.totalTime or -1))
end
print(race.winner(r) or "No winner: nobody finished")
pitwall.stop()
