-- tests/integration/drive_browser_test.sh: cars 1 and 2 driven by people from the /drive page
-- (pitwall run --view 0 --humans 2 --cars 2). No race director: the cars drive as soon as a
-- phone gives throttle, and stand while nobody does.
local drivers = require "pitwall.drivers"
local track = require "pitwall.track"

local human = drivers.load("human")
local map = track.fromSim()
local cars = pitwall.cars()
for i = 1, 2 do
  local car = cars[i]
  drivers.run(car, human.new { seat = i, min = 300, max = 800 }, drivers.context(car, map, cars))
end
pitwall.log("info", "drive race: seats 1 and 2 are open on /drive")
