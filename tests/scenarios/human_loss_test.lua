-- Human drivers when their input goes (docs/racing.md "Human drivers"): a phone that drops out
-- while the race director drives its car (the scan lap) does not stop the race; seats a script
-- opened itself stop their cars when a reload takes them away; a human driver given another
-- car's seat says so.
-- tags: race
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local drivers = require "pitwall.drivers"
local human = drivers.load("human")

local seats = sim.openSeats(1)
local cars = { sim.addCar {}, sim.addCar {} }

-- Seat 1's phone is there at first, drops out during the scan lap (its car, car 1, is the scan
-- car), and is back, giving throttle, once the race is green.
local feeding, throttle = true, 0
pitwall.spawn(function()
  while true do
    if feeding then seats[1]:feed(throttle) end
    pitwall.sleep(0.1)
  end
end)
local scanning, lostDuringScan = false, false
pitwall.spawn(function()
  pitwall.waitUntil(function() return sim.truth(cars[1]).speed > 0 end, 10, 0.01)
  scanning = true
  pitwall.sleep(2)
  feeding = false -- the phone locks mid-scan
  pitwall.waitUntil(function() return not seats[1].live end, 3, 0.01)
  lostDuringScan = not seats[1].live
end)
local r = race.laps {
  laps = 1, scan = true, results = false, board = false,
  drivers = function(car, i)
    if i == 1 then return human.new { seat = 1 } end
    return drivers.load("cruiser").new { speed = 700 }
  end,
  onLights = function(k, session)
    if k < 5 then return end
    pitwall.spawn(function()
      pitwall.waitUntil(function() return session.green end, 5, 0.005)
      feeding, throttle = true, 0.9 -- back, and driving
    end)
  end,
}
expect.truthy(scanning, "car 1 drove the scan lap")
expect.truthy(lostDuringScan, "seat 1 lost its input during the scan lap")
expect.eq(#r.map.pieces, #sim.track().pieces, "the scan lap mapped the whole track")
for _, row in ipairs(r:results()) do expect.truthy(row.finished, row.car .. " finished") end

-- A human driver given another car's seat: an error naming both, and the car is not driven.
local errors = {}
pitwall.onError = function(message) errors[#errors + 1] = message end
local wrong = drivers.run(cars[2], human.new { seat = 1 }, drivers.context(cars[2], r.map, cars))
pitwall.sleep(0.5)
wrong:stop()
pitwall.onError = nil
expect.truthy(#errors > 0, "the mismatch is reported")
expect.truthy(tostring(errors[1]):find("seat 1 drives car 1", 1, true), "it names the seat's car: "
  .. tostring(errors[1]))

-- A version of a script that opened its own seats and drove from them is reloaded into one
-- without: its seats go, and the car driven from them is stopped.
feeding = false
local v1 = [[
local sim = require "pitwall.sim"
local drivers = require "pitwall.drivers"
local track = require "pitwall.track"
local car = pitwall.cars()[1]
local seats = sim.openSeats(1)
drivers.run(car, drivers.load("human").new { seat = 1, max = 900 },
  drivers.context(car, track.fromSim(), { car }))
while true do seats[1]:feed(1) pitwall.sleep(0.1) end
]]
local s = sim.script(v1)
pitwall.sleep(3)
local car = cars[1]
expect.truthy(s.started, "the script under test started")
expect.gt(sim.truth(car).speed, 500, "the script's human driver drives")
sim.reload("-- being edited: no seats, no driver")
pitwall.sleep(3)
expect.eq(sim.truth(car).speed, 0, "the car driven from the gone seats stopped")
pitwall.stop()
