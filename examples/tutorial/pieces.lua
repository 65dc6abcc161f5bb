-- Tutorial step 2 (docs/tutorial.md): learn the track, then react to every piece the car enters:
-- fast on straights, slower in and before curves.
--
--   build/pitwall run examples/tutorial/pieces.lua --cars 1

local track = require "pitwall.track"
local localize = require "pitwall.localize"

local FAST = tonumber(os.getenv("FAST")) or 1400   -- mm/s on straights
local SLOW = tonumber(os.getenv("SLOW")) or 800    -- mm/s in curves

local car = pitwall.cars()[1]
print("scanning the track: a slow lap or two")
local map, here = track.scan(car)          -- a slow lap (or two) that learns the pieces
print(map)

local loc = localize.follow(car, map)      -- follows the car on that map, piece by piece
loc:assume(here)                           -- the piece the scan stopped on
car:setSpeed(SLOW, 4000)
car:changeLane(-68)                        -- the inside lane: the shortest lap, the tightest curves

loc:subscribe { enter = function(loc, index, from, time)
  local piece = map.pieces[index]
  local after = map.pieces[map:next(index)]
  local speed = (piece.type == "curve" or after.type == "curve") and SLOW or FAST
  print(string.format("%6.2f s  piece %d (%s): %d mm/s", time, index, piece.type, speed))
  car:setSpeed(speed, 4000)
end }

car.onDelocalized = function(car, ev)
  print(string.format("%6.2f s  %s came off the track", ev.time, car.name))
end

pitwall.sleep(10)
pitwall.stop()
