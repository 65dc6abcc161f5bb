-- A track of custom pieces (docs/tracks.md): its own ids, lengths, radii and angles. Cars on it
-- report the design's piece ids; pitwall.piece knows the custom shapes; a scan lap maps it back
-- to the same layout; lap times agree with its length; AI drivers race a grand prix on it.
-- tags: track
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local laps = require "pitwall.laps"
local race = require "pitwall.race"

local LAYOUT = "start S:60,len=440 L:61,r=400,deg=45 L:61,r=400,deg=45 L:61,r=400,deg=45 "
  .. "L:61,r=400,deg=45 S:60,len=440 S:36 L:62,r=200,deg=90 S:64,len=400 L:62,r=200,deg=90"
local t = sim.setTrack(LAYOUT)
expect.eq(#t.pieces, 12, "pieces")

-- pitwall.piece: the design's shapes for its own ids, Anki's for the stock ones
local c = pitwall.piece(61)
expect.eq(c.type, "curve", "61 is a curve")
expect.eq(c.radius, 400, "61's radius")
expect.eq(c.angle, 45, "61's angle")
expect.near(c.length, 400 * math.pi / 4, 1e-9, "61's length")
expect.truthy(c.custom, "61 is custom")
expect.near(pitwall.piece(60).length, 440, 1e-9, "60's length")
expect.eq(pitwall.piece(36).length, 560, "36 is Anki's")
expect.eq(pitwall.piece(36).custom, nil, "36 is not custom")
expect.eq(pitwall.piece(65), nil, "an id the track does not have")

-- The scan lap maps it: ids, turns, shapes and lengths.
local scout = sim.addCar { name = "scout", lane = 2, piece = 2 }
local seen = {}
pitwall.listen(scout, "onPosition", function(_, e) seen[e.piece] = (seen[e.piece] or 0) + 1 end)
local map = track.scan(scout, { speed = 400 })
expect.eq(map:layout(true), LAYOUT:gsub("^start ", "start "), "the scan's layout is the design")
expect.near(map:lapLength(0), sim.track().lapLength, 0.01, "the map's lap length is the design's")
-- lapLength keeps what it summed (track.lua): asked again, and for more offsets than it keeps,
-- it is the sum of the pieces' lengths every time; NaN is asked like any offset
for round = 1, 2 do
  for o = -90, 90, 10 do
    local sum = 0
    for _, p in ipairs(map.pieces) do sum = sum + p:length(o) end
    expect.eq(map:lapLength(o), sum, "the lap length at offset " .. o .. ", round " .. round)
  end
end
expect.truthy(map:lapLength(0 / 0) ~= map:lapLength(0 / 0), "a NaN offset gives NaN, no error")
for _, id in ipairs { 34, 33, 60, 61, 36, 62, 64 } do
  expect.gt(seen[id] or 0, 0, "position updates on piece " .. id)
end
scout:stop()
sim.run(2)

-- Lap times agree with the lap's length in the car's lane, at a steady speed.
local runner = sim.addCar { name = "runner", lane = 4, piece = 8 } -- beside the standing scout
local timer = laps.timer(runner, map)
runner:setSpeed(500, 2000)
expect.truthy(sim.runUntil(function() return timer.count >= 3 end, 60), "three laps timed")
local offset = sim.truth(runner).offset
local expected = map:lapLength(offset) / 500
for i, lap in ipairs(timer.history) do
  if i > 1 then -- the first lap began at the start of the timing, not on the line
    expect.near(lap.time, expected, 0.01 * expected, "lap " .. i .. " time at 500 mm/s")
  end
end
runner:stop()
scout:stop()
