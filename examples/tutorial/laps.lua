-- Tutorial step 3 (docs/tutorial.md): step 2's car with lap times; the run ends after LAPS laps.
--
--   build/pitwall run examples/tutorial/laps.lua --cars 1
--   build/pitwall run examples/tutorial/laps.lua --cars 1 --view   -- and open http://127.0.0.1:8080/

local track = require "pitwall.track"
local localize = require "pitwall.localize"
local laps = require "pitwall.laps"

local FAST = tonumber(os.getenv("FAST")) or 1400   -- mm/s on straights
local SLOW = tonumber(os.getenv("SLOW")) or 800    -- mm/s in curves
local LAPS = tonumber(os.getenv("LAPS")) or 5      -- laps to drive

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
  car:setSpeed((piece.type == "curve" or after.type == "curve") and SLOW or FAST, 4000)
end }

car.onDelocalized = function(car, ev)
  print(string.format("%6.2f s  %s came off the track", ev.time, car.name))
end

laps.timer(car, map, {
  onLap = function(car, lap)
    local text = string.format("%s lap %d: %.3f s", car.name, lap.number, lap.time)
    print(string.format("%6.2f s  %s", pitwall.now(), text))
    pitwall.view.event(text)                       -- a line in the race view's event log
    if lap.number == LAPS then pitwall.stop() end  -- stops the car and ends the run
  end,
})
