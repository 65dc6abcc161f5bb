-- pitwall.sim.script and sim.reload, the scenario's script under test: started on the next turn
-- of the loop with the cars' events, replaced at a given engine time, refused versions counted,
-- a dying script reported, the cars stopped and handed back to the scenario when it stops; bad
-- arguments refused with what to do.
-- tags: reload
local sim = require "pitwall.sim"

expect.fails(function() sim.reload("x = 1") end, "no script under test to reload")

-- every code: the scenario counts the position events its handler hears
sim.sensor { model = "ideal" }
local car = sim.addCar {}
local heard = 0
car.onPosition = function() heard = heard + 1 end

local run = sim.script([[
local car = pitwall.cars()[1]
car:setSpeed(500)
car.onPosition = function() end
]], { name = "first.lua" })
expect.falsy(run.started, "started on the next turn of the loop, not inside this call")
expect.fails(function() sim.script("x = 1") end, "already running")
sim.run(1)
expect.truthy(run.started, "started")
expect.eq(run.version, 1)
expect.near(sim.truth(car).targetSpeed, 500, 0, "the script under test drives the car")
local before = heard
sim.run(1)
expect.eq(heard, before, "the scenario's own handler is silent while the script under test runs")

-- at: an engine time; in the past means at once; not a number, or not a time, is refused
expect.fails(function() sim.reload("x = 1", 1e300) end, "is not an engine time")
expect.fails(function() sim.reload("x = 1", 0 / 0) end, "must be a finite number")
expect.fails(function() sim.reload("x = 1", "soon") end, "must be a number")
sim.reload("pitwall.cars()[1]:setSpeed(700)", pitwall.now() - 5)
sim.reload("pitwall.cars()[1]:setSpeed(900) end", pitwall.now() + 1) -- does not compile
sim.reload("pitwall.cars()[1]:setSpeed(600)", pitwall.now() + 2)
sim.run(0.5)
expect.eq(run.version, 2, "the save in the past came at once")
expect.near(sim.truth(car).targetSpeed, 700, 0)
sim.run(1)
expect.eq(run.refused, 1, "the broken save was refused")
expect.truthy(run.refusal:find("first.lua:1:", 1, true), "with its name and line: " .. run.refusal)
expect.near(sim.truth(car).targetSpeed, 700, 0, "and the running version carried on")
sim.run(1)
expect.eq(run.version, 3)
expect.near(sim.truth(car).targetSpeed, 600, 0)

-- a version whose main chunk dies after it started: reported, its cars stopped, a fix loads
sim.reload("pitwall.cars()[1]:setSpeed(800) pitwall.sleep(0.5) error('gave up')")
sim.run(1)
expect.truthy(run.died, "the script died")
expect.eq(sim.truth(car).targetSpeed, 0, "its car stopped")
sim.reload("pitwall.cars()[1]:setSpeed(400) pitwall.sleep(1) pitwall.stop()")
sim.run(0.5)
expect.falsy(run.died, "the fix runs")
expect.near(sim.truth(car).targetSpeed, 400, 0)

-- pitwall.stop(): the script is done, its car stopped, the scenario has the car back
expect.truthy(sim.runUntil(function() return run.finished end, 5), "it stopped")
sim.run(0.1)
expect.eq(sim.truth(car).targetSpeed, 0, "its car stopped")
car:setSpeed(300)
before = heard
sim.run(1)
expect.gt(heard, before, "the scenario's handler hears the car again")

-- the next script under test, once the first finished
local second = sim.script("pitwall.cars()[1]:setSpeed(650)")
sim.run(0.5)
expect.near(sim.truth(car).targetSpeed, 650, 0, "a second script under test")
expect.eq(second.version, 1)

-- a car that joins while the script under test runs is its car (pitwall.onCar): the world that
-- takes the car hooks its events from inside the fleet's own connection handler
sim.reload("pitwall.onCar = function(car) car:setSpeed(550) end")
sim.run(0.5)
local third = sim.addCar {}
sim.run(0.5)
expect.near(sim.truth(third).targetSpeed, 550, 0, "the late car driven by the script under test")
expect.eq(second.version, 2)
