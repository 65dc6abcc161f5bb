-- Human drivers (docs/racing.md "Human drivers"): two seats fed a scripted input sequence, as a
-- phone or a gamepad would, race two AI drivers. The director treats them like anyone: grid,
-- lights, a human's jump start caught and held, laps, results in the order their throttles make.
-- Then input loss: a seat that falls silent has its car slowed to a stop by the engine.
-- tags: race
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local track = require "pitwall.track"
local drivers = require "pitwall.drivers"
local human = drivers.load("human")

local seats = sim.openSeats(2)
expect.eq(#seats, 2, "two seats")
expect.eq(#pitwall.seats(), 2, "pitwall.seats")
local cars = {}
for i = 1, 4 do cars[i] = sim.addCar {} end
expect.eq(seats[1].car, cars[1], "seat 1 drives car 1")
expect.eq(seats[2].car, cars[2], "seat 2 drives car 2")
expect.falsy(seats[1].held, "a seat is free until someone takes it")

-- The scripted input: what each seat's holder asks for now, sent every 0.1 s (a phone's rate).
local want = { { throttle = 0 }, { throttle = 0 } }
local feeding = { true, true }
for i = 1, 2 do
  pitwall.spawn(function()
    while feeding[i] do
      seats[i]:feed(want[i].throttle, want[i].lane or 0)
      want[i].lane = nil
      pitwall.sleep(0.1)
    end
  end)
end

local laneAsked, offsetBefore
local r = race.laps {
  laps = 3, map = track.fromSim(), results = false, board = false, falseStartPenalty = 3,
  drivers = function(car, i)
    if i <= 2 then return human.new { seat = i, max = 1200, assist = true } end
    return drivers.load("cruiser").new { speed = 750 }
  end,
  onLights = function(k, session)
    if k == 3 then want[2].throttle = 0.5 end -- human 2 cannot wait: a jump start
    if k == 5 then
      pitwall.spawn(function()
        pitwall.waitUntil(function() return session.green end, 5, 0.005)
        want[1].throttle = 1 -- human 1 floors it at green
        want[2].throttle = 0.2 -- and human 2, chastened, dawdles
        pitwall.sleep(4)
        offsetBefore = sim.truth(cars[1]).offset
        want[1].lane, laneAsked = 1, pitwall.now() -- one lane to the right
      end)
    end
  end,
}

local rows = r:results()
expect.eq(#rows, 4, "four cars in the results")
expect.eq(rows[1].laps, 3, "the winner drove the 3 laps")
for k, row in ipairs(rows) do
  expect.eq(row.position, k, "positions in order")
  expect.truthy(row.finished, row.car .. " finished")
  -- a car finishes when it next crosses the line after the winner: a lap down, or on it
  expect.truthy(row.laps == 3 or row.laps == 2, row.car .. " laps: " .. tostring(row.laps))
  if k > 1 then
    local prev = rows[k - 1]
    expect.truthy(prev.laps > row.laps or (prev.laps == row.laps and prev.totalTime <= row.totalTime),
      row.car .. " ranked by laps, then time")
  end
  expect.eq(row.falseStart, row.car == cars[2].name, row.car .. " false start flag")
end
expect.eq(rows[1].car, cars[1].name, "the human at full throttle wins")
expect.eq(rows[4].car, cars[2].name, "the human who jumped and dawdled is last")
expect.gt(r:entry(cars[2]).releaseAt, r.green + 2.9, "the jumper was held for the penalty")
expect.truthy(laneAsked, "the lane step was asked")
local entry = r:entry(cars[1])
expect.eq(entry.driver.name, "human", "a human driver in the race")

-- Lane steps move the car: right of where it was, by one lane (45 mm).
expect.near(sim.truth(cars[1]).offset - offsetBefore, 45, 12, "one lane to the right")

-- Input loss. Human 1 drives again outside a race; then its input stops (a phone that went
-- silent) while its driver keeps running: the car is stopped within the 1 s silence and the
-- braking from its speed, and the driver does not drive it off again. (The driver and the engine
-- both ask for the stop here; the engine's own, with no driver, is tests/unit/drive/seats_test.)
local handle = drivers.run(cars[1], human.new { seat = 1, max = 1000 },
  drivers.context(cars[1], track.fromSim(), cars))
want[1].throttle = 0.8
pitwall.waitUntil(function() return sim.truth(cars[1]).speed > 700 end, 10, 0.05)
expect.gt(sim.truth(cars[1]).speed, 700, "the human drives")
expect.truthy(seats[1].live, "seat 1 live while fed")
feeding[1] = false
local lastFed = pitwall.now()
local stopped = pitwall.waitUntil(function() return sim.truth(cars[1]).speed == 0 end, 5, 0.01)
expect.truthy(stopped, "the car stopped after its input was lost")
expect.falsy(seats[1].live, "seat 1 lost its input")
expect.eq(seats[1].throttle, 0, "a lost seat reads throttle 0")
-- 1 s of silence (give or take the feeding period), then 850 mm/s braked at 1500 mm/s²
expect.lt(pitwall.now() - lastFed, 1.1 + 850 / 1500 + 0.3, "stopped in time")
pitwall.sleep(2)
expect.eq(sim.truth(cars[1]).speed, 0, "and stays stopped while its driver runs")
handle:stop()

-- What a script feeds is checked like a phone's input.
feeding[2] = false
seats[2]:release()
expect.falsy(seats[2].held, "released")
expect.fails(function() seats[2]:feed(2) end, "throttle 2 is out of range", "a throttle of 2")
expect.fails(function() seats[2]:feed(0 / 0) end, "the throttle must be a finite number", "NaN")
expect.fails(function() seats[2]:feed(0.5, 5) end, "lane step must be -1", "a lane step of 5")
expect.truthy(tostring(seats[1]):find("seat 1 (script", 1, true), "tostring names the holder")
pitwall.stop()
