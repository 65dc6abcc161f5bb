-- Human drivers on whatever cars the run has (race_cli_test.sh runs it on the simulator and over
-- --ble): the script holds seats 1 and 2 (seat:feed, as a phone would, 10 times a second), waits
-- for green before it gives throttle, and races two cruisers for LAPS laps (default 1). Then input
-- loss: car 1 driven by its human driver, the feed stops, and the engine must stop the car.
local race = require "pitwall.race"
local drivers = require "pitwall.drivers"
local human = drivers.load("human")

local seats = pitwall.seats()
assert(#seats == 2, "run it with --humans 2")
local want, feeding = { 0, 0 }, true
for i, seat in ipairs(seats) do
  pitwall.spawn(function()
    while feeding do
      seat:feed(want[i])
      pitwall.sleep(0.1)
    end
  end)
end

local r = race.laps {
  laps = tonumber(os.getenv("LAPS")) or 1,
  scan = true,
  drivers = function(car, i)
    if seats[i] then return human.new { seat = i, max = 1000 } end
    return drivers.load("cruiser").new { speed = 800 }
  end,
  onLights = function(k, session)
    if k < 5 then return end
    pitwall.spawn(function()
      pitwall.waitUntil(function() return session.green end, 5, 0.005)
      want[1], want[2] = 0.8, 0.6
    end)
  end,
}
for _, row in ipairs(r:results()) do
  print(string.format("%s %s laps=%d finished=%s falseStart=%s", row.car,
    r:entry(pitwall.car(row.car)).driver.name, row.laps, tostring(row.finished),
    tostring(row.falseStart)))
end

-- Input loss: the feed of seat 1 stops while its human driver keeps running.
local car = seats[1].car
local handle = drivers.run(car, human.new { seat = 1, max = 800 },
  drivers.context(car, r.map, pitwall.cars()))
want[1] = 0.8
local moving = pitwall.waitUntil(function() return (car.speed or 0) > 400 end, 10, 0.05)
feeding = false
local lost = pitwall.now()
local stopped = pitwall.waitUntil(function()
  -- (a stopped car reports no positions: its last reported speed is that of its braking)
  return not seats[1].live and car.targetSpeed == 0 and not drivers.moving(car)
end, 5, 0.05)
print(string.format("input loss: moving=%s stopped=%s after %.1f s", tostring(moving),
  tostring(stopped), pitwall.now() - lost))
handle:stop()
pitwall.stop()
