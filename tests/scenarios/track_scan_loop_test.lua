-- A track without the start/finish piece — the okoeth oval of the real captures
-- (tests/realdata), R:17 R:18 S:40 R:18 R:23 S:39, whose ids repeat (18 twice) — is mapped by
-- track.scan under the real sensor model in every lane at a slow and a race speed: the lap
-- closed by its curves' turn, the same six pieces as the simulator's, every id it names where
-- the simulator has it. Laps are then counted at the line the script names (line = 17: the
-- beginning of the simulator's first piece, where the simulator counts its own) equal to the
-- simulator's, from a tracker told where the scan left the car (docs/racing.md "Mapping any
-- loop").
-- tags: track
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local laps = require "pitwall.laps"

sim.setTrack("R:17 R:18 S:40 R:18 R:23 S:39")
local truth = track.fromSim()
expect.eq(truth.hasStart, false, "the simulator's map: no start piece")
expect.eq(truth:layout(true), "R:17 R:18 S:40 R:18 R:23 S:39", "the simulator's layout")

local car = sim.addCar { lane = 1, piece = 3 }
for _, lane in ipairs { -68, -23, 23, 68 } do
  for _, speed in ipairs { 250, 750 } do
    local what = string.format("lane %d at %d mm/s", lane, speed)
    local map, here = track.scan(car, { offset = lane, speed = speed, stop = false, timeout = 200 })
    expect.eq(map.hasStart, false, what .. ": no start piece")
    expect.eq(#map.pieces, 6, what .. ": six pieces")
    -- the same as the simulator's from some piece on (the scan's line is where it began)
    local fits = false
    for r = 1, 6 do
      local ok = true
      for i, p in ipairs(map.pieces) do
        local t = truth.pieces[(r - 2 + i) % 6 + 1]
        if p.type ~= t.type or p.turn ~= t.turn or (p.id ~= nil and p.id ~= t.id) then ok = false end
      end
      fits = fits or ok
    end
    expect.truthy(fits, what .. ": the simulator's pieces in order: " .. map:layout(true))
    expect.near(map:lapLength(0), truth:lapLength(0), 0.01, what .. ": the lap's length")
    car:stop()
    sim.run(2)
  end
end

-- Laps at the line the script names, counted as the simulator counts them.
local map, here = track.scan(car, { line = 17, stop = false })
expect.eq(map:layout(true):sub(1, 4), "R:17", "the line before piece 17: " .. map:layout(true))
local timer = laps.timer(car, map)
timer.localization:assume(here)
car:setSpeed(700)
sim.run(1)
local before = sim.truth(car).laps
sim.run(40)
expect.gt(timer.count, 5, "laps counted")
-- compared half way round, away from a crossing still on its way
local lap = map:lapLength(0)
expect.truthy(sim.runUntil(function()
  local d = sim.truth(car).lapDistance
  return d > 0.4 * lap and d < 0.6 * lap
end, 15), "half way round")
expect.eq(timer.count, sim.truth(car).laps - before - 1,
  "as many laps as the simulator, the first crossing starting lap 1")
car:stop()
