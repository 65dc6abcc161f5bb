-- The start: lights, green, and a false start (a car that moves before green is stopped, held
-- for the penalty after green, and flagged in the results).
-- tags: race
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local track = require "pitwall.track"

local cars = {}
for i = 1, 3 do cars[i] = sim.addCar {} end

local lights, jumped, jumpedAt = {}, {}, nil
local r = race.laps {
  laps = 2, map = track.fromSim(), results = false, board = false, falseStartPenalty = 4,
  drivers = function() return race.Steady.new { speed = 700 } end,
  onLights = function(k, session)
    lights[#lights + 1] = pitwall.now()
    -- the jump, between two of the race's periodic checks (0.1 s apart, from the light on)
    if k == 3 then pitwall.after(0.03, function() cars[2]:setSpeed(400) end) end
  end,
  onFalseStart = function(car)
    jumped[#jumped + 1] = car
    jumpedAt = jumpedAt or pitwall.now()
  end,
}
expect.eq(#lights, 5, "five lights")
expect.near(lights[5] - lights[1], 4, 0.001, "a light a second, to the ms")
expect.eq(#jumped, 1, "one false start")
expect.eq(jumped[1], cars[2], "by the car that moved")
-- judged as the car acknowledges the speed (or reports moving), not at the next period's check
expect.le(jumpedAt - (lights[3] + 0.03), 0.04, "judged within 40 ms of the jump (its speed acknowledged)")
expect.near(r.green - lights[5], 0.5, 0.001, "green half a second after the last light")
local rows = r:results()
for _, row in ipairs(rows) do
  expect.eq(row.falseStart, row.car == cars[2].name, row.car .. " flagged")
end
expect.eq(rows[3].car, cars[2].name, "the jumper, held 4 s, is last")
expect.gt(r:entry(cars[2]).releaseAt, r.green + 3.9, "held for the penalty")

-- The hold itself: a second race (the cars first driven back to the grid), watching the
-- jumper's true speed from green until its penalty is over.
local held = true
local session
session = race.laps {
  laps = 1, map = track.fromSim(), results = false, board = false, falseStartPenalty = 3,
  drivers = function() return race.Steady.new { speed = 700 } end,
  onLights = function(k, s)
    session = s
    if k == 1 then cars[3]:setSpeed(300) end
    if k == 5 then
      -- watch the jumper from green until the end of its penalty
      pitwall.spawn(function()
        pitwall.waitUntil(function() return s.green end, 5, 0.005)
        while pitwall.now() < s.green + 2.9 do
          if sim.truth(cars[3]).speed > 0 then held = false end
          pitwall.sleep(0.05)
        end
      end)
    end
  end,
}
expect.truthy(held, "the jumper did not move during its penalty")
expect.truthy(session:results()[1].falseStart == false, "the winner did not jump")
for _, c in ipairs(cars) do expect.eq(sim.truth(c).speed, 0, tostring(c) .. " stopped") end
