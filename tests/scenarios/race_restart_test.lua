-- A race aborted mid-way and a new one started with scan = true: no second scan lap (the map of
-- the session before is used), and the cars are brought to the grid from wherever they stopped —
-- two of them put in one lane, one behind the other, so that one must move across. Then a car
-- that cannot get there: the error names it and says why.
-- tags: race
local sim = require "pitwall.sim"
local race = require "pitwall.race"

local cars = {}
for i = 1, 4 do cars[i] = sim.addCar {} end
local function steady(_, i) return race.Steady.new { speed = 500 + 100 * i } end

local first = race.new { mode = "laps", laps = 5, scan = true, drivers = steady, board = false,
  results = false }
pitwall.spawn(function()
  pitwall.waitUntil(function() return first.state == "racing" end)
  pitwall.sleep(3)
  first:abort()
end)
first:run()
expect.eq(first.state, "done", "the first race was aborted")
local scanned = sim.truth(cars[1]).laps

-- Cars 1 and 2 into one lane, car 2 one piece ahead of car 1, away from the start.
local t = sim.track()
local k34
for k, p in ipairs(t.pieces) do if p.id == 34 then k34 = k end end
local n = #t.pieces
for i, k in ipairs { (k34 + 2) % n + 1, (k34 + 3) % n + 1 } do
  sim.lift(cars[i])
  sim.run(0.1)
  sim.place(cars[i], k, -68)
end
sim.run(0.5)

local atLights = {}
local second = race.laps { laps = 2, scan = true, drivers = steady, board = false, results = false,
  gridTimeout = 60,
  onLights = function(k)
    if k == 1 then
      for i, c in ipairs(cars) do atLights[i] = sim.truth(c) end
    end
  end }
expect.eq(sim.truth(cars[1]).laps - scanned >= 2, true, "car 1 raced")
expect.eq(second.map, first.map, "the first race's map: no second scan lap")
for i = 1, 4 do
  expect.eq(atLights[i].piece, 34, "car " .. i .. " on the grid at the first light")
  for j = 1, i - 1 do
    expect.ge(math.abs(atLights[i].offset - atLights[j].offset), 40,
      "cars " .. j .. " and " .. i .. " in lanes of their own")
  end
end
for _, row in ipairs(second:results()) do
  expect.eq(row.laps, 2, row.car .. " raced the second race")
  expect.truthy(row.finished, row.car .. " finished")
end
for _, c in ipairs(cars) do expect.eq(sim.truth(c).collisions, 0, tostring(c) .. " hit nobody") end

-- A car lifted off the track cannot get to the grid: the error says which and why.
sim.lift(cars[3])
local err = expect.fails(function()
  race.laps { laps = 1, drivers = steady, board = false, results = false, gridTimeout = 15 }
end, "1 car(s) did not reach the grid (piece 34) in 15 s")
expect.truthy(err:find(tostring(cars[3]), 1, true), "names the car: " .. err)
expect.truthy(err:find("not known", 1, true), "says why: " .. err)
expect.falsy(err:find(tostring(cars[1]), 1, true), "the others got there: " .. err)
sim.run(0.1)
for _, c in ipairs(cars) do expect.eq(sim.truth(c).targetSpeed, 0, tostring(c) .. " stopped") end
