-- Tutorial step 6 (docs/tutorial.md): your car in a real race — grid, start lights, laps,
-- leaderboard, results — against a friend on a phone, or against one of pitwall's AI drivers.
--
--   build/pitwall run examples/tutorial/race.lua --cars 2 --humans 1 --view 0.0.0.0:8080
--     your friend opens the /drive address it prints on a phone and drives car 1
--   build/pitwall run examples/tutorial/race.lua --cars 2 --humans 1 --keyboard
--     your friend drives car 1 with the arrow keys of this terminal
--   build/pitwall run examples/tutorial/race.lua --cars 2 --view    -- car 1 is the AI "cruiser"

local race = require "pitwall.race"
local drivers = require "pitwall.drivers"

local FAST = tonumber(os.getenv("FAST")) or 1400   -- mm/s on straights
local SLOW = tonumber(os.getenv("SLOW")) or 800    -- mm/s in curves
local LAPS = tonumber(os.getenv("LAPS")) or 5

-- Step 2's rule as a driver: the race calls update(car, ctx) ten times a second.
local mine = { name = "mine" }
function mine:update(car, ctx)
  local speed = SLOW
  local index = ctx.loc.index                      -- the map piece the car is on, if known
  if index then
    local piece = ctx.map.pieces[index]
    local after = ctx.map.pieces[ctx.map:next(index)]
    if piece.type ~= "curve" and after.type ~= "curve" then speed = FAST end
  end
  speed = drivers.cap(ctx, speed)                  -- the race's speed limit, when it sets one
  if car.targetSpeed ~= speed then car:setSpeed(speed, 4000) end
end

-- With --humans 1, seat 1 (car 1) is your friend's: wait for them to take it.
local seat = pitwall.seat(1)
if seat and not seat.held then
  print("waiting for a player on car 1: open the /drive address above on a phone")
  pitwall.waitUntil(function() return seat.held end, 300)
end

local session = race.laps { laps = LAPS, scan = true, title = "Tutorial race",
  drivers = function(car, i)
    if i == 1 and seat and seat.held then return drivers.load("human").new { seat = 1 } end
    if i == 1 then return drivers.load("cruiser").new { speed = 1000 } end
    return mine                                    -- every other car: your driver
  end }
print(race.winner(session))
pitwall.stop()
