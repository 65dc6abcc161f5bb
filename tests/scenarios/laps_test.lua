-- Laps counted from position updates (34 → 33) match the simulator's ground truth on the oval,
-- at several speeds and lanes, and lap times match lap length / speed.
-- tags: track
local sim = require "pitwall.sim"
-- Every code: this counts laps from the position events themselves, which a real car at speed
-- does not send on every piece (docs/simulator.md "Sensor model"; pitwall.laps counts
-- transitions too: tests/scenarios/lap_timing_test.lua).
sim.sensor { model = "ideal" }

local cases = {
  { speed = 400, lane = 1 },
  { speed = 700, lane = 2 },
  { speed = 1000, lane = 4 },
}

local cars = {}
for i, c in ipairs(cases) do
  local car = sim.addCar { lane = c.lane, piece = 1, distance = 10 * i }
  car.laps, car.times = 0, {}
  car.onPosition = function(car, ev)
    if ev.piece == 33 and car.last == 34 then
      if car.lapStart then
        car.laps = car.laps + 1
        car.times[#car.times + 1] = ev.time - car.lapStart
      end
      car.lapStart = ev.time
    end
    car.last = ev.piece
  end
  car:setSpeed(c.speed, 25000)
  cars[i] = car
end

sim.run(60)

local offsets = { -68, -23, 23, 68 }
for i, car in ipairs(cars) do
  local truth = sim.truth(car)
  -- The first crossing only starts the clock, so one lap fewer than the simulator counted.
  expect.eq(car.laps, truth.laps - 1, car.name .. " laps")
  expect.ge(car.laps, 4, car.name .. " laps in 60 s")
  -- The lane's length over the speed; inner lanes of left curves are shorter.
  local lane = offsets[cases[i].lane]
  local length = 0
  for _, p in ipairs(sim.track().pieces) do
    length = length + (p.turn == 0 and p.length or (280 + lane * p.turn) * math.pi / 2)
  end
  local expected = length / cases[i].speed
  for lap, t in ipairs(car.times) do
    expect.near(t, expected, 0.02, string.format("%s lap %d time", car.name, lap))
  end
end
