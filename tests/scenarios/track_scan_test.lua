-- A scan lap on the oval builds its map: piece ids, types, turns, count, the finish line and
-- the lengths per lane; the car stops on the piece the scan says it is on. track.scan refuses to run
-- outside a task, and track.fromSim gives the same map without driving.
-- tags: track
local sim = require "pitwall.sim"
local track = require "pitwall.track"

local car = sim.addCar { lane = 2, piece = 4 } -- starts in a curve: the scan must find the line
local started = pitwall.now()
local map, here = track.scan(car)
local took = pitwall.now() - started

-- The simulator's own layout, from the piece after the finish line on.
local truth = sim.track()
local n = #truth.pieces
expect.eq(#map.pieces, n, "pieces")
expect.eq(map.finishIndex, 1, "finish index")
for i, p in ipairs(map.pieces) do
  local t = truth.pieces[(truth.finishIndex - 2 + i) % n + 1]
  local what = string.format("piece %d", i)
  expect.eq(p.index, i, what .. " index")
  expect.eq(p.id, t.id, what .. " id")
  expect.eq(p.type, t.type, what .. " type")
  expect.eq(p.turn, t.turn > 0 and "left" or t.turn < 0 and "right" or nil, what .. " turn")
  expect.near(p:length(), t.length, 0.01, what .. " centre length")
end
expect.eq(map.pieces[1].id, 33, "the first piece follows the finish line")
expect.eq(map.pieces[n].id, 34, "the last piece leads to the finish line")
expect.eq(map:layout(), "start S L L S S L L", "layout")
expect.eq(map:layout(true), "start S:36 L:17 L:18 S:39 S:40 L:20 L:23", "layout with ids")
expect.near(map.scanOffset, -23, 0.5, "scan lane")

-- Lengths: the centre lap as the simulator has it; left curves are shorter inside (−68).
expect.near(map:lapLength(0), truth.lapLength, 0.01, "centre lap")
expect.near(map:lapLength(-68), 2240 + 4 * (280 - 68) * math.pi / 2, 0.01, "inner lap")
expect.near(map:lapLength(68), 2240 + 4 * (280 + 68) * math.pi / 2, 0.01, "outer lap")
expect.near(map.pieces[3]:length(68), 546.64, 0.01, "outer lane of a left curve")
expect.eq(map.pieces[2]:length(68), 560, "a straight is the same in every lane")
expect.near(map.pieces[n].start + map.pieces[n]:length(), map:lapLength(0), 0.01, "starts add up")
expect.eq(#map:find(17), 1, "piece 17 occurs once")

-- Under two laps at 350 mm/s (≈11.4 s a lap), then stopped where the scan says it is: map
-- piece `here` (or, coasting to a stop, the one after).
expect.lt(took, 25, "scan time")
local function truthIndex(k) return (truth.finishIndex - 2 + k) % n + 1 end
expect.eq(sim.truth(car).pieceIndex, truthIndex(here), "on map piece `here` when the scan ends")
sim.run(1)
local t = sim.truth(car)
expect.eq(t.speed, 0, "the car stops after the scan")
expect.truthy(t.pieceIndex == truthIndex(here) or t.pieceIndex == truthIndex(here + 1),
  "stopped on map piece `here` or the next")
expect.eq(map.hasStart, true, "the oval has its start piece")

-- Without a task there is no waiting: a clear error.
local err
pitwall.after(0, function()
  local ok, e = pcall(track.scan, car)
  err = ok and "no error" or e
end)
sim.run(0.1)
expect.truthy(err and err:find("inside a task", 1, true), "scan in a timer: " .. tostring(err))
expect.fails(function() track.scan(car, { speed = 5 }) end, "outside 100..1000")

-- The simulator's map without a scan is the same map.
local fromSim = track.fromSim()
expect.eq(fromSim:layout(true), map:layout(true), "fromSim layout")
expect.near(fromSim:lapLength(-23), map:lapLength(-23), 0.01, "fromSim lap length")

-- stop = false leaves the car driving at the scan speed.
local again = track.scan(car, { speed = 500, stop = false })
expect.eq(again:layout(true), map:layout(true), "a second scan")
sim.run(1)
expect.near(sim.truth(car).speed, 500, 1, "still driving after stop = false")

-- A car that drives reversed is turned round first, and the map is the same.
car:uturn()
sim.run(1)
expect.truthy(car.reverse, "driving reversed before the scan")
local turned = track.scan(car)
expect.falsy(car.reverse, "driving forward after the scan")
expect.eq(turned:layout(true), map:layout(true), "a scan that began reversed")
