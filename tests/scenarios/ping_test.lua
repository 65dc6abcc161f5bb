-- A ping comes back as onPing with the round-trip time over the simulator link (two hops of the
-- link's latency); battery and version requests are answered too.
-- tags: sim
local sim = require "pitwall.sim"

local car = sim.addCar {}
local rtt, battery, version
car.onPing = function(car, ev) rtt = ev.rtt end
car.onBattery = function(car, ev) battery = ev.millivolts end
car.onVersion = function(car, ev) version = ev.version end

car:ping()
car:battery()
car:version()
expect.truthy(sim.runUntil(function() return rtt and battery and version end, 1), "all answered")
expect.near(rtt, 0.020, 0.0015, "round trip over the sim link")
expect.eq(car.lastPing, rtt)
expect.gt(battery, 3000, "battery millivolts")
expect.eq(car.batteryLevel, battery)
expect.eq(version, 0x2b70)
expect.eq(car.firmware, version)
