-- The map of a track, learnt by driving car 1 round it (track.scan), or by watching a car that
-- drives on its own: a record or a real car's capture replayed (track.learn). It works on tracks
-- without the start/finish piece and with cars that send no position update at all: the lap is
-- closed by its curves' turn (docs/racing.md "Mapping any loop").
--
--   build/pitwall run examples/map_track.lua --fast                      -- the simulator's oval
--   build/pitwall run examples/map_track.lua --ble                       -- real cars
--   WATCH=1 build/pitwall replay tests/realdata/okoeth/lane4_speed250.txt --script examples/map_track.lua
--
-- It prints the layout (`R R S R R S`: curves right and left, straights; an id after a colon
-- where a position update named the piece) and each piece.
local track = require "pitwall.track"

local car = pitwall.cars()[1]
if not car then
  print("no car: give one (--cars 1, --ble) or a record to replay")
  return pitwall.stop()
end
local map, here
if os.getenv("WATCH") then
  map, here = track.learn(car)
else
  map, here = track.scan(car)
end
print(string.format("%s: %d pieces, %.0f mm a lap on the centre line, %s", tostring(car),
  #map.pieces, map:lapLength(0), map.hasStart and "laps at the finish line"
    or "no start piece: laps where the scan began"))
print("layout: " .. map:layout(true))
for _, p in ipairs(map.pieces) do print("  " .. tostring(p)) end
print(string.format("%s is on piece %d", tostring(car), here))
pitwall.stop()
