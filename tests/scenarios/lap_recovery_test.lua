-- A car that leaves the track, is lifted and put back, or turns round neither gains nor loses a
-- lap. The simulator counts every forward crossing of the finish line made on the track; the
-- timer counts a crossing only after most of the lap was driven, so where the two must differ
-- (a car put back behind the line, a car that backed over it and crossed it again) the test
-- says so.
-- tags: track sim
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local localize = require "pitwall.localize"
local laps = require "pitwall.laps"

local map = track.fromSim()
local n, simFinish = #map.pieces, sim.track().finishIndex
local function simIndex(m) return (m + simFinish - 2) % n + 1 end
local function mapIndex(s) return (s - simFinish) % n + 1 end

local car = sim.addCar { lane = 1, piece = 1 }
local loc = localize.follow(car, map)
local timer = laps.timer(car, map)
local SPEED = 800
car:setSpeed(SPEED, 25000)
local laneLap = map:lapLength(-68)

local function behind() return sim.truth(car).laps - timer.count end
local function at(m) return function() return mapIndex(sim.truth(car).pieceIndex) == m end end

sim.run(20)
expect.ge(timer.count, 3, "laps before anything happens")
expect.eq(behind(), 1, "the first crossing only starts lap 1")
local best = timer.best.time
expect.near(best, laneLap / SPEED, 0.01, "a clean lap's time")

-- 1. Too fast in a bend: it leaves the track, and is put back on the piece where it stopped.
-- (Told so on a straight, it enters the next curve at 1500 mm/s and flies off; one that reaches
-- a little over the limit inside a curve slides on, simulator.md "Delocalization".)
expect.truthy(sim.runUntil(function()
  return sim.track().pieces[sim.truth(car).pieceIndex].type ~= "curve"
end, 10), "on a straight")
car:setSpeed(1500, 25000)
expect.truthy(sim.runUntil(function() return car.delocalized end, 10), "delocalized")
expect.falsy(loc.localized, "not localized off the track")
sim.run(2)
local stoppedOn = sim.truth(car).pieceIndex
sim.place(car, stoppedOn, -68)
car:setSpeed(SPEED, 25000)
local count = timer.count
expect.truthy(sim.runUntil(function() return timer.count > count end, 10), "the interrupted lap ends")
expect.falsy(timer.last.clean, "the interrupted lap is not clean")
expect.gt(timer.last.time, best + 1, "it took longer")
sim.run(12)
expect.eq(behind(), 1, "after leaving the track: no lap gained or lost")
expect.eq(timer.best.time, best, "the best lap stays a clean one")
expect.truthy(timer.last.clean, "laps after it are clean again")

-- 2. Lifted on the first bend and put back before the finish line: the simulator counts the
-- crossing that follows, the timer does not (a fifth of a lap was driven); the lap after it
-- is a full one.
expect.truthy(sim.runUntil(at(3), 10), "reaches the first bend")
sim.lift(car)
sim.run(1)
sim.place(car, simIndex(n), -68)
car:setSpeed(SPEED, 25000)
count = timer.count
expect.truthy(sim.runUntil(function() return timer.count > count end, 15), "a lap after")
expect.eq(behind(), 2, "put back before the line: the simulator's extra crossing is not a lap")
expect.truthy(timer.last.clean, "the lap from the line on is clean")
expect.near(timer.last.time, laneLap / SPEED, 0.01, "and a full lap's time")

-- 3. Lifted near the end of the lap and put back after the line: no crossing, and the lap
-- still counts where it ends (most of it was driven), slow and not clean.
expect.truthy(sim.runUntil(at(7), 10), "reaches the last bends")
sim.lift(car)
sim.run(1)
sim.place(car, simIndex(2), -68)
car:setSpeed(SPEED, 25000)
count = timer.count
expect.truthy(sim.runUntil(function() return timer.count > count end, 15), "the lap ends")
expect.eq(behind(), 2, "put back after the line: no lap gained or lost")
expect.falsy(timer.last.clean, "that lap is not clean")

-- 4. Turned round on the first straight, backed over the finish line, turned round again:
-- crossing the line forward again is not a lap; the next one is.
expect.truthy(sim.runUntil(at(2), 10), "on the first straight")
count = timer.count
car:uturn()
expect.truthy(sim.runUntil(at(n - 1), 10), "backed over the line into the last bend")
sim.run(0.05) -- the transition's frame is on its way
expect.truthy(loc.reverse, "the tracker knows it drives reversed")
expect.eq(loc.index, n - 1, "and where")
car:uturn()
expect.truthy(sim.runUntil(at(2), 10), "forward over the line again")
sim.run(0.5)
expect.eq(timer.count, count, "no lap for backing over the line and crossing it again")
expect.truthy(sim.runUntil(function() return timer.count > count end, 10), "the next lap")
expect.eq(behind(), 3, "the simulator counted the second forward crossing")
expect.near(timer.last.time, laneLap / SPEED, 0.01, "a full lap from the line")
