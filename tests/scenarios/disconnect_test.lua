-- A dropped connection: onDisconnect says why, the car stops, commands to it fail with a clear
-- error instead of vanishing, and the other cars carry on.
-- tags: sim
local sim = require "pitwall.sim"

local gone = sim.addCar { lane = 1 }
local other = sim.addCar { lane = 4 }
local reason
gone.onDisconnect = function(car, ev) reason = ev.reason end

gone:setSpeed(700)
other:setSpeed(700)
sim.run(3)
gone:disconnect()
expect.truthy(sim.runUntil(function() return reason ~= nil end, 1), "onDisconnect within 1 s")
expect.truthy(reason:find("disconnect"), "the reason: " .. reason)
expect.falsy(gone.connected)

local err = expect.fails(function() gone:setSpeed(500) end, "not connected")
expect.truthy(err:find(tostring(gone), 1, true), "the error names the car")
expect.fails(function() gone:ping() end, "not connected")

sim.run(3)
expect.eq(sim.truth(gone).speed, 0, "a disconnected car stops")
expect.gt(sim.truth(other).speed, 600, "the other car drives on")
