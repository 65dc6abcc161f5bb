-- Localization against the simulator's ground truth: the distance from the finish line, the
-- piece and the lane of four cars at four speeds in four lanes, sampled every 12.5 ms; then
-- with 5 % of the frames lost; while stopping; through lane changes; driving reversed; and
-- after being lifted and put back elsewhere. The figures printed are those in docs/racing.md.
-- tags: track
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local localize = require "pitwall.localize"

-- The nearest lane: halfway between two, the first (the one further left); NaN, the first.
for _, c in ipairs { { 0, -23 }, { -45.5, -68 }, { 45.5, 23 }, { -45.4, -23 }, { 45.6, 68 },
  { 30, 23 }, { -1e9, -68 }, { 1e9, 68 }, { 0 / 0, -68 }, { -23, -23 } } do
  expect.eq(localize.nearestLane(c[1]), c[2], "nearest lane to " .. tostring(c[1]))
end

local map = track.fromSim()
local n, simFinish = #map.pieces, sim.track().finishIndex
local LAP = map:lapLength(0)
local LANES = { -68, -23, 23, 68 }
local function mapIndex(s) return (s - simFinish) % n + 1 end

local cases = {
  { speed = 400, lane = 4 },
  { speed = 700, lane = 3 },
  { speed = 1000, lane = 1 },
  { speed = 1300, lane = 2 },
}
local cars, locs = {}, {}
for i, c in ipairs(cases) do
  cars[i] = sim.addCar { lane = c.lane, piece = 1 + i, distance = 100 }
  locs[i] = localize.follow(cars[i], map)
end
expect.eq(localize.follow(cars[1], map), locs[1], "one tracker per car and map")
expect.falsy(locs[1].localized, "not localized before the car has moved")
expect.eq(locs[1]:distance(), nil, "no distance before")

-- Samples the error (mm, along the centre line, across the finish line too) for `seconds`.
local function measure(seconds, which)
  local stats = {}
  for _, i in ipairs(which) do stats[i] = { max = 0, sum = 0, count = 0, wrongPiece = 0 } end
  local stop = pitwall.now() + seconds
  while pitwall.now() < stop do
    pitwall.sleep(0.0125)
    for _, i in ipairs(which) do
      local loc = locs[i]
      if loc.anchored then
        local d, index = loc:locate()
        local truth = sim.truth(cars[i])
        local err = math.abs((d - truth.lapDistance + LAP / 2) % LAP - LAP / 2)
        local s = stats[i]
        s.max, s.sum, s.count = math.max(s.max, err), s.sum + err, s.count + 1
        if index ~= mapIndex(truth.pieceIndex) then s.wrongPiece = s.wrongPiece + 1 end
      end
    end
  end
  for _, s in pairs(stats) do s.mean = s.count > 0 and s.sum / s.count or math.huge end
  return stats
end

local function report(label, i, s)
  print(string.format("%-22s %4d mm/s lane %3d: max %5.1f mm, mean %5.1f mm, %4.1f %% on the previous piece",
    label, cases[i].speed, locs[i].lane, s.max, s.mean, 100 * s.wrongPiece / s.count))
end

local all = { 1, 2, 3, 4 }
for i, car in ipairs(cars) do car:setSpeed(cases[i].speed, 25000) end
sim.run(3)

-- Noise off. The error is mostly the frames' age: 10 ms on the link plus up to one 5 ms tick.
local stats = measure(60, all)
for i, s in pairs(stats) do
  local v = cases[i].speed
  report("noise off", i, s)
  expect.gt(s.count, 4000, "samples")
  expect.le(s.max, 0.02 * v + 5, "max error (mm)")
  expect.le(s.mean, 0.012 * v, "mean error (mm)")
  expect.lt(s.wrongPiece / s.count, 0.05, "share on the previous piece")
  expect.eq(locs[i].lane, LANES[cases[i].lane], "lane")
  expect.near(locs[i].speed, v, 1, "speed")
  expect.near(locs[i]:fraction(), locs[i]:distance() / LAP, 1e-9, "fraction")
end

-- 5 % of the frames lost.
sim.noise { drop = 0.05 }
stats = measure(60, all)
for i, s in pairs(stats) do
  local v = cases[i].speed
  report("5 % lost", i, s)
  expect.le(s.max, 0.03 * v + 10, "max error with noise (mm)")
  expect.le(s.mean, 0.012 * v, "mean error with noise (mm)")
end
sim.noise { drop = 0 }

-- Stopping: the speed update says how hard the car brakes; the estimate stops where it does.
for _, car in ipairs(cars) do car:stop() end
sim.run(2)
for i, car in ipairs(cars) do
  local truth = sim.truth(car)
  expect.eq(truth.speed, 0, "stopped")
  local err = math.abs((locs[i]:distance() - truth.lapDistance + LAP / 2) % LAP - LAP / 2)
  expect.le(err, 10, string.format("car %d: error once stopped (mm)", i))
end

-- One car on its own from here (the others leave the track, and are no obstacle).
for i = 2, 4 do sim.lift(cars[i]) end
local car, loc = cars[1], locs[1]
cases[1].speed = 700
car:setSpeed(700, 2000)
sim.run(2)

-- Lane changes from one side to the other and back, every 4 s.
local changing = true
pitwall.spawn(function()
  local lane = 68
  while changing do
    lane = -lane
    car:changeLane(lane, 150, 1000)
    pitwall.sleep(4)
  end
end, "lane changes")
stats = measure(30, { 1 })
report("changing lanes", 1, stats[1])
-- Under the real sensor model a curve at 700 mm/s sends few position updates: through a lane
-- change there the tracker reckons with the last reported offset's lane length (78 mm; 27 mm
-- with every code, docs/racing.md "Accuracy").
expect.le(stats[1].max, 100, "max error while changing lanes (mm)")
expect.le(stats[1].mean, 15, "mean error while changing lanes (mm)")
changing = false
sim.run(4)
expect.truthy(sim.runUntil(function() return not car.laneChanging end, 5), "lane changes over")
car:uturn()

-- Driving reversed: the pieces come the other way round, the distance goes down.
sim.run(1)
expect.truthy(loc.reverse, "reversed")
local before = loc:distance()
sim.run(0.2)
local after = loc:distance()
expect.lt((after - before + LAP / 2) % LAP - LAP / 2, 0, "the distance goes down")
stats = measure(20, { 1 })
report("reversed", 1, stats[1])
-- (42 mm under the real sensor model, 9 mm with every code: docs/racing.md "Accuracy")
expect.le(stats[1].max, 60, "max error reversed (mm)")
expect.lt(stats[1].wrongPiece / stats[1].count, 0.05, "share on the previous piece reversed")

-- Lifted, and put back elsewhere on another lane: lost, then found on the right piece.
sim.lift(car)
sim.run(0.5)
expect.falsy(loc.localized, "lost when lifted")
expect.eq(loc:distance(), nil, "no distance when lost")
sim.place(car, 6, -23)
car:setSpeed(700, 2000)
expect.truthy(sim.runUntil(function() return loc.localized end, 5), "found again")
expect.falsy(loc.reverse, "place() puts the car forward")
expect.truthy(sim.runUntil(function() return loc.anchored end, 5), "anchored by a transition")
sim.run(0.05)
expect.eq(loc.index, mapIndex(sim.truth(car).pieceIndex), "on the right piece")
expect.eq(loc.lane, -23, "in its new lane")
stats = measure(20, { 1 })
report("put back elsewhere", 1, stats[1])
-- (34 mm under the real sensor model, 9 mm with every code)
expect.le(stats[1].max, 60, "max error after being put back (mm)")
