-- The soak's race (tests/integration/ble_soak_test.sh): a timed grand prix of every car found
-- over Bluetooth LE, SECONDS long (default 300), with the race library's own drivers, while the
-- fake BlueZ injects link faults. Up to 4 cars a scan lap maps the track; more race on the
-- layout given with --track (a scan lap would run into the grid's second row). Prints the race's sentence and one line per car
-- ("car N status=… laps=… reconnects=…"), for the test to read; the results go to --results.
local race = require "pitwall.race"
local drivers = require "pitwall.drivers"

local SECONDS = tonumber(os.getenv("SECONDS_LONG")) or 300
local lineup = { "cruiser", "lanekeeper", "follower", "overtaker" }

local cars = pitwall.cars()
print(string.format("soak: %d cars, %d s", #cars, SECONDS))
local gp = race.timed {
  seconds = SECONDS,
  scan = #cars <= 4,
  drivers = function(car, i)
    return drivers.load(lineup[(i - 1) % #lineup + 1]).new { speed = 900 + 50 * (i % 4) }
  end,
  title = "Soak",
  finishTimeout = 30,
}
print(race.winner(gp) or "No winner: nobody finished")
for _, row in ipairs(gp:results()) do
  local car = pitwall.car(row.number)
  local link = car.link
  print(string.format("car %d status=%s laps=%d connected=%s drops=%d connects=%d "
    .. "writeFailures=%d stalls=%d silences=%d longestSilence=%.1f roundTrip=%s", row.number,
    row.status, row.laps, tostring(car.connected), link.drops, link.connects, link.writeFailures,
    link.stalls, link.silences, link.longestSilence, tostring(link.roundTrip)))
end
pitwall.stop()
