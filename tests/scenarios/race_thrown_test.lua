-- A car that takes curves a little too fast (a lane keeper holding the inside lane, its cruiser at
-- 1450 mm/s with lateral 12000; the simulator throws a car above 9000 mm/s², and one thrown by less
-- than 1.15 times that slides on: 1450²/212 ≈ 9900) slides off its line at the first curve,
-- still on the road, and loses the code for a while, as a real car does. The marshal (docs/racing.md
-- "What a session does") drives it on at 400 mm/s at most until it is found again, and lowers
-- that curve's limit for it to 85 % of the speed it was thrown at: it is thrown at most once per
-- curve, and finishes. Without the marshal it was thrown at every curve of every lap (20 times
-- in 4 laps: the lane keeper takes it back to the inside lane each time).
-- tags: race
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local drivers = require "pitwall.drivers"

local fast = sim.addCar {}   -- grid slot 1: the inside lane (−68 mm)
local other = sim.addCar {}
local thrown, searching = {}, {}
local function session(marshal)
  return race.laps {
    laps = 4,
    board = false,
    marshal = marshal,
    drivers = function(car)
      if car == fast then
        return drivers.load("lanekeeper").new { offset = -68, speed = 1450, lateral = 12000 }
      end
      return drivers.load("cruiser").new { speed = 700 }
    end,
    onThrown = function(car, info)
      thrown[#thrown + 1] = { car = car, info = info, at = pitwall.now() }
    end,
  }
end

-- the target while it is not found yet, from 0.15 s after it slid (the marshal looks every
-- 0.1 s): every 50 ms
local slid, slidAt = 0, nil
pitwall.every(0.05, function()
  local t = sim.truth(fast)
  if t.slides ~= slid then slid, slidAt = t.slides, pitwall.now() end
  if t.delocalized and t.onTrack and slidAt and pitwall.now() >= slidAt + 0.15 then
    searching[#searching + 1] = t.targetSpeed
  end
end)

local r = session(true)
local rows = {}
for _, row in ipairs(r:results()) do rows[row.car] = row end
local slides = sim.truth(fast).slides
expect.gt(slides, 0, "the fast car was thrown")
expect.eq(#thrown, slides, "every throw seen by the marshal")
local curves = 0
for _, p in ipairs(r.map.pieces) do if p.type == "curve" then curves = curves + 1 end end
local pieces = {}
for _, t in ipairs(thrown) do
  expect.eq(t.car, fast, "only the fast car")
  expect.eq(r.map.pieces[t.info.piece].type, "curve", "thrown off a curve")
  expect.falsy(pieces[t.info.piece], "not twice off piece " .. t.info.piece)
  pieces[t.info.piece] = true
  expect.near(t.info.limit, 0.85 * t.info.speed, 1, "the curve's limit: 85 % of its speed")
end
expect.le(slides, curves, "at most once per curve")
expect.eq(rows[fast.name].laps, 4, "the fast car finished its 4 laps")
expect.truthy(rows[fast.name].finished, "and took the flag")
expect.gt(#searching, 0, "it was seen searching")
local driven = 0
for _, v in ipairs(searching) do
  expect.le(v, 400, "asked at most 400 mm/s while not found")
  driven = math.max(driven, v)
end
expect.gt(driven, 0, "and driven, not stopped, while not found")
