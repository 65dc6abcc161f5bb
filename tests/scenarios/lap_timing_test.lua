-- Lap timing on a scanned oval: lap counts equal the simulator's finish crossings, lap times
-- equal the ground truth's (crossing to crossing) and the lane's length over the speed, at
-- four speeds in four lanes; sectors add up; onLap and onBestLap carry the laps. Then 5 % of
-- the frames are lost: the counts stay exact.
-- tags: track
local sim = require "pitwall.sim"
-- As real cars report: position updates thin out with speed, none on most curves at 1000 mm/s
-- and up; the laps come from the transitions (docs/simulator.md "Sensor model").
expect.eq(sim.sensor().model, "real", "the default")
sim.sensor { model = "real" }
expect.eq(sim.sensor().model, "real")
local track = require "pitwall.track"
local laps = require "pitwall.laps"

local LANES = { -68, -23, 23, 68 }
local cases = {
  { speed = 1300, lane = 2 }, -- the scout: it scans the track, then races
  { speed = 400, lane = 4 },
  { speed = 700, lane = 3 },
  { speed = 1000, lane = 1 },
}

local cars = {}
for i, c in ipairs(cases) do
  cars[i] = sim.addCar { lane = c.lane, piece = 1, distance = 15 * (i - 1) }
end
local map = track.scan(cars[1], { stop = false })
expect.eq(map:layout(), "start S L L S S L L", "scanned layout")

-- Ground truth: the times at which the simulator counted a finish crossing (5 ms ticks).
local crossings = {}
for i in ipairs(cars) do crossings[i] = {} end
pitwall.spawn(function()
  local seen = {}
  for i, car in ipairs(cars) do seen[i] = sim.truth(car).laps end
  while true do
    for i, car in ipairs(cars) do
      local n = sim.truth(car).laps
      if n ~= seen[i] then
        seen[i] = n
        local list = crossings[i]
        list[#list + 1] = pitwall.now()
      end
    end
    pitwall.sleep(0.005)
  end
end, "truth")

local timers, events, bests = {}, {}, {}
local lastBest = {}
for i, car in ipairs(cars) do
  events[i], bests[i] = {}, 0
  timers[i] = laps.timer(car, map, {
    onLap = function(c, lap)
      expect.eq(c, car, "onLap's car")
      events[i][#events[i] + 1] = { number = lap.number, time = lap.time, at = pitwall.now() }
    end,
  })
end
laps.onBestLap = function(c, lap)
  local i = c.number
  bests[i] = bests[i] + 1
  if lastBest[i] then expect.lt(lap.time, lastBest[i], "a new best is faster") end
  lastBest[i] = lap.time
end
for i, car in ipairs(cars) do car:setSpeed(cases[i].speed, 25000) end

local START = pitwall.now()
sim.run(90)

-- Counts are compared in the middle of a lap, away from a crossing still on its way.
local function midLap(car)
  local lap = map:lapLength(0)
  expect.truthy(sim.runUntil(function()
    local d = sim.truth(car).lapDistance
    return d > 0.4 * lap and d < 0.6 * lap
  end, 15), "half way round")
end

local function laneLap(i)
  return map:lapLength(LANES[cases[i].lane])
end

-- Compares every counted lap with the ground truth; returns the largest difference (s).
local function checkLaps(i, from, tolerance, label)
  local timer, truth = timers[i], crossings[i]
  local worst = 0
  for _, lap in ipairs(timer.history) do
    if lap.start >= from then
      -- The truth's crossings nearest to the lap's start and finish (ours come 10–15 ms later:
      -- the link's latency and the tick).
      local a, b
      for _, t in ipairs(truth) do
        if math.abs(t - lap.start) < 0.5 then a = t end
        if math.abs(t - lap.finish) < 0.5 then b = t end
      end
      local what = string.format("%s car %d lap %d", label, i, lap.number)
      expect.truthy(a and b, what .. ": matching crossings in the ground truth")
      local diff = math.abs(lap.time - (b - a))
      worst = math.max(worst, diff)
      expect.le(diff, tolerance, what .. ": time vs ground truth")
      expect.near(lap.time, laneLap(i) / cases[i].speed, tolerance + 0.005, what .. ": time vs lane length / speed")
    end
  end
  return worst
end

local counts, truths = {}, {} -- at the end of this part, for the next
for i, car in ipairs(cars) do
  local timer = timers[i]
  local what = string.format("car %d (%d mm/s, lane %d)", i, cases[i].speed, LANES[cases[i].lane])
  -- The first crossing after the timer started starts lap 1.
  midLap(car)
  expect.eq(timer.count, #crossings[i] - 1, what .. ": laps vs ground truth crossings")
  counts[i], truths[i] = timer.count, #crossings[i]
  expect.ge(timer.count, math.floor(90 * cases[i].speed / laneLap(i)) - 1, what .. ": laps in 90 s")
  expect.eq(#events[i], timer.count, what .. ": onLap calls")
  for k, e in ipairs(events[i]) do expect.eq(e.number, k, what .. ": onLap numbers") end
  local worst = checkLaps(i, START + 1, 0.01, "noise off:")
  print(string.format("%s: %d laps, %.3f s each, worst difference to the ground truth %.1f ms",
    what, timer.count, timer.average, worst * 1000))

  -- Last, best, average; every lap was clean.
  expect.eq(timer.last, timer.history[#timer.history], what .. ": last")
  expect.truthy(timer.best and timer.best.clean, what .. ": best is a clean lap")
  expect.ge(bests[i], 1, what .. ": onBestLap calls")
  expect.eq(lastBest[i], timer.best.time, what .. ": the last onBestLap is the best")
  local sum = 0
  for _, lap in ipairs(timer.history) do
    expect.truthy(lap.clean, what .. ": clean lap")
    sum = sum + lap.time
  end
  expect.near(timer.average, sum / #timer.history, 1e-9, what .. ": average")

  -- Sectors: from the line to the straight after the first bends, and from there home.
  local last = timer.last
  expect.eq(#last.sectors, 2, what .. ": sectors")
  expect.near(last.sectors[1] + last.sectors[2], last.time, 1e-9, what .. ": sectors add up")
  local first = 0
  for k = 1, 4 do first = first + map.pieces[k]:length(LANES[cases[i].lane]) end
  expect.near(last.sectors[1], first / cases[i].speed, 0.012, what .. ": sector 1 time")
end

-- 5 % of the frames lost: the counts stay exact, the times within 20 ms (a crossing whose
-- transition was lost is reckoned from the speed).
sim.noise { drop = 0.05 }
local NOISY = pitwall.now()
sim.run(180)
for i, car in ipairs(cars) do
  local what = string.format("noise on: car %d", i)
  midLap(car)
  local gained = timers[i].count - counts[i]
  expect.eq(gained, #crossings[i] - truths[i], what .. ": laps vs ground truth")
  expect.gt(gained, 10, what .. ": laps in 180 s")
  local worst = checkLaps(i, NOISY + 1, 0.02, "noise on:")
  print(string.format("noise on: car %d: %d laps, worst difference to the ground truth %.1f ms", i,
    gained, worst * 1000))
end

-- Bad input is refused with the reason.
expect.fails(function() laps.timer(cars[1], map, { sectors = { 2, 5 } }) end, "beginning with 1")
expect.fails(function() laps.timer(cars[1], map, { sectors = { 1, 5, 3 } }) end, "entry 3")
expect.fails(function() laps.timer(cars[1], {}) end, "track map")
