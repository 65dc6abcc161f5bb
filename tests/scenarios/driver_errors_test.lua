-- A driver whose update keeps failing (a typo: setSped) slows its car to a stop (docs/safety.md
-- "A car whose script keeps failing"): five failures within 10 s stop the car through the
-- vehicle model, the script's commands to it are refused from then on, and the race goes on for
-- the other car, whose driver works.
-- tags: drivers errors
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local drivers = require "pitwall.drivers"

local errors = {}
pitwall.onError = function(message, where) errors[#errors + 1] = where .. ": " .. message end

local map = track.fromSim()
local a = sim.addCar { lane = 1, piece = 2 }
local b = sim.addCar { lane = 4, piece = 6 }
local broken = {
  name = "broken",
  start = function(self, car) car:setSpeed(800) end,
  update = function(self, car, ctx) car:setSped(900) end,  -- raises on every update
}
drivers.run(a, broken, drivers.context(a, map, { a, b }))
drivers.run(b, drivers.load("cruiser").new { speed = 700 }, drivers.context(b, map, { a, b }))
local fastest = 0
local watch = pitwall.every(0.01, function() fastest = math.max(fastest, sim.truth(a).speed) end)
sim.run(5)
watch:cancel()
expect.gt(fastest, 100, "the broken driver's car got going before it failed enough")
expect.eq(sim.truth(a).speed, 0, "the broken driver's car is stopped")
expect.eq(a.targetSpeed, 0, "its last command was the stop")
expect.fails(function() a:setSpeed(500) end, "takes no command from this script")
expect.gt(sim.truth(b).speed, 600, "the other car races on")
expect.truthy(errors[1]:find("update of driver broken", 1, true), "where: " .. errors[1])
