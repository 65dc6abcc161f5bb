-- Free practice and a timed qualifying: no lights in practice, the default driver (cruiser),
-- each car's lap under way when the time runs out is its last, best lap first; bad options.
-- tags: race
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local track = require "pitwall.track"

local cars = {}
for i = 1, 3 do cars[i] = sim.addCar {} end
local map = track.fromSim()

local lights = 0
local t0 = pitwall.now()
local p = race.practice { seconds = 15, map = map, results = false, board = false,
  onLights = function() lights = lights + 1 end }
expect.eq(lights, 0, "no lights in practice")
expect.near(p.green, t0, 0.01, "practice starts at once")
for _, row in ipairs(p:results()) do
  expect.truthy(row.finished, row.car .. " finished its session")
  expect.gt(row.totalTime, 15, row.car .. " crossed the line after the time")
  expect.le(row.totalTime - row.lastLap, 15, row.car .. " its last lap began before the time")
  expect.ge(row.laps, 2, row.car .. " laps")
end
for _, c in ipairs(cars) do expect.eq(sim.truth(c).speed, 0, tostring(c) .. " stopped") end

local q = race.qualifying { seconds = 20, map = map, results = false, board = false,
  drivers = function(car, i) return race.Steady.new { speed = 500 + 150 * i } end }
local rows = q:results()
expect.eq(rows[1].car, cars[3].name, "pole")
for k = 2, #rows do expect.ge(rows[k].bestLap, rows[k - 1].bestLap, "best lap order") end
for _, row in ipairs(rows) do
  expect.le(row.totalTime - row.lastLap, 20, row.car .. " its last lap began before the time")
end

expect.fails(function() race.laps { map = map } end, "laps = N")
expect.fails(function() race.timed { map = map } end, "minutes")
expect.fails(function() race.new { mode = "drag" } end, "unknown mode")
expect.fails(function() race.laps { laps = 1, map = map, drivers = 42 } end, "driver")
