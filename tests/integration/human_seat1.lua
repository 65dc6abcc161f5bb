-- Car 1 driven by a person from seat 1 (--humans 1 with --keyboard or --gamepads): the race
-- library's human driver, and a line every quarter second saying what the seat asks and what
-- the car does, for tests/integration/keyboard_pty_test.py and tests/qemu/gamepad_guest.sh:
--   seat 1: holder=keyboard throttle=0.30 speed=512 moving=yes truth=498
-- speed: the car's last report (it keeps its last value once the car stands, as a real car
-- sends nothing at rest); moving: a position report within the last 0.5 s (drivers.moving: a
-- rolling car on a curve at speed may report none for longer); truth: the simulator's own
-- speed of the car (0: it stands), for the checks that must know it.
local drivers = require "pitwall.drivers"
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local human = drivers.load("human")

local car = pitwall.cars()[1]
local seat = pitwall.seat(1)
drivers.run(car, human.new { seat = 1 }, drivers.context(car, track.fromSim(), {}))
pitwall.every(0.25, function()
  print(string.format("seat 1: holder=%s throttle=%.2f speed=%d moving=%s truth=%d",
    tostring(seat.holder), seat.throttle, math.floor((car.speed or 0) + 0.5),
    drivers.moving(car) and "yes" or "no", math.floor(sim.truth(car).speed + 0.5)))
  io.stdout:flush()
end)
