-- The final of a league (pitwall run --league-final DB, docs/league.md "The final"): the league's
-- top drivers race on the cars of this run — real ones with --ble — with the same driver files and
-- rules as in the league: each in a driver world of its own, the league's laps, the grid in the
-- order of the league's standings (its winner on pole: car 1). pitwall.final says who
-- ({title, laps, league, drivers = {names, pole first}}); pitwall.driverFiles[n] is the file of
-- car n's driver. The results go to the league's standings database as a final.
local race = require "pitwall.race"

local final = pitwall.final
if not final then
  pitwall._raise("league_final.lua races a league's final: run it with --league-final DB")
end
local cars = {}
for _, car in ipairs(pitwall.cars()) do
  if pitwall.driverFiles[car.number] then cars[#cars + 1] = car end
end
table.sort(cars, function(a, b) return a.number < b.number end)
for number, name in ipairs(final.drivers) do
  if not cars[number] or cars[number].number ~= number then
    pitwall.log("warn", string.format("final: %s has no car: car %d is not here", name, number))
  end
end
if #cars < 2 then
  pitwall._raise(string.format("final: %d of the %d finalists have a car: a final needs 2 "
    .. "(connect more cars, or give fewer with --final-cars)", #cars, #final.drivers))
end
pitwall.log("info", string.format("final: %s, %d %s: %s", final.title, final.laps,
  final.laps == 1 and "lap" or "laps", table.concat(final.drivers, ", ", 1, #cars)))
local session = race.laps {
  cars = cars, laps = final.laps, title = final.title, scan = #cars <= 4, finishTimeout = 30,
  grid = cars,
}
print(race.winner(session) or "No winner: nobody finished")
pitwall.stop()
