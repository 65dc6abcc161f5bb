-- Personal bests an adversary would plant (tests/integration/ghost_run_test.sh): car 1 drives
-- free at 1000 mm/s before its race, which it then drives at 500 (the kept best must be the
-- race's lap, not the free one); then the script keeps results of its own with a made-up
-- trace and layout for "mallory" (never kept), and entries numbered otherwise than the cars.
local race = require "pitwall.race"
local drivers = require "pitwall.drivers"
local car = pitwall.cars()[1]
car:setSpeed(1000)
pitwall.sleep(15)
car:stop()
pitwall.sleep(2)
local r = race.laps { laps = 2,
  drivers = function() return drivers.load("cruiser").new { speed = 500 } end }
for _, row in ipairs(r:results()) do
  print(string.format("race best: %s %s %.3f", row.car, row.car, row.bestLap))
end
local trace = { lap = 1, time = 0.8, length = 3999.292, points = { { 0, 0, 0, 0 }, { 0.8, 3999.292, 0, 0 } } }
print("planted:", pitwall.keepResults { kind = "race", number = 1, track = "oval", laps = 1,
  layout = "start S:36 L:17 L:18 S:39 S:40 L:20 L:23", green = 0,
  entries = { { number = 2, car = "groundshock", driver = "mallory", laps = 1, bestLap = 0.8,
    bestTrace = trace }, { number = 1, car = "skull", driver = "eve", laps = 1, bestLap = 1 } } })
pitwall.stop()
