-- A scan of a car that sends no position update at all (the transitions sensor model: the
-- worst case, docs/simulator.md; a real car in lane 4 at 250 mm/s sent none in two laps) maps
-- the track all the same: the lap is closed by its curves' turn, pieces and turns come from the
-- wheel distances, the start piece's halves from their lengths (docs/racing.md "Mapping any
-- loop"). The ids it never saw stay unknown, and a tracker on that map counts laps.
-- tags: track
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local laps = require "pitwall.laps"
sim.sensor { model = "transitions" }
local car = sim.addCar { lane = 1, piece = 4 }
local started = pitwall.now()
local map, here = track.scan(car)
local took = pitwall.now() - started
local truth = track.fromSim()
expect.eq(map:layout(), truth:layout(), "the same pieces, turns and start as the simulator's")
expect.eq(map.hasStart, true, "the start piece found by its halves' lengths")
expect.eq(map.pieces[1].id, 33, "the finish line first")
for i, p in ipairs(map.pieces) do
  if p.type ~= "start-short" and p.type ~= "start-long" then
    expect.eq(p.id, nil, "piece " .. i .. ": no id (no position update ever named it)")
  end
end
expect.near(map:lapLength(0), truth:lapLength(0), 0.01, "the lap's length")
expect.lt(took, 30, "under three laps at the scan speed")
local simTrack = sim.track()
expect.eq(sim.truth(car).pieceIndex, (simTrack.finishIndex - 2 + here) % #map.pieces + 1,
  "the car is on map piece `here`")
sim.run(2)
expect.eq(sim.truth(car).speed, 0, "the car stopped")

-- Laps on that map, from transitions alone, once the tracker is told where the car stands.
local timer = laps.timer(car, map)
timer.localization:assume(here)
car:setSpeed(600)
local lapsBefore = sim.truth(car).laps
sim.run(30)
expect.gt(timer.count, 0, "laps counted")
expect.eq(timer.count, sim.truth(car).laps - lapsBefore - 1, "as many as the simulator's, but the first crossing starts lap 1")
car:stop()
