-- The race director, timed race: when the time runs out the leader's lap under way is its last;
-- every other car finishes at its next crossing after that. Checked against ground truth.
-- tags: race
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local track = require "pitwall.track"

local speeds = { 1000, 850, 700, 550 }
local cars = {}
for i = 1, 4 do cars[i] = sim.addCar {} end

local truthLaps, green = {}, nil
local r = race.timed {
  seconds = 20, map = track.fromSim(), results = false, board = false,
  drivers = function(car, i) return race.Steady.new { speed = speeds[i] } end,
  onFinish = function(car) truthLaps[car] = sim.truth(car).laps end,
}
local rows = r:results()
local winner = rows[1]
expect.eq(winner.car, cars[1].name, "the fastest car wins")
-- its last lap began before the time ran out and ended after it
expect.gt(winner.totalTime, 20, "the winner's last crossing is after the time")
expect.le(winner.totalTime - winner.lastLap, 20, "its lap before began before the time ran out")
-- a 1000 mm/s car on the inside lane (3572 mm): 20 s make 5.6 laps → 6 laps
expect.eq(winner.laps, 6, "the winner's laps")
for k, row in ipairs(rows) do
  expect.truthy(row.finished, row.car .. " finished")
  expect.eq(row.laps, truthLaps[pitwall.car(row.car)] - 1, row.car .. " laps vs truth")
  if k > 1 then
    expect.ge(row.totalTime, winner.totalTime, row.car .. " crossed after the winner")
    expect.lt(row.totalTime - row.lastLap, winner.totalTime,
      row.car .. " finished at its first crossing after the winner")
  end
end
for _, c in ipairs(cars) do expect.eq(sim.truth(c).speed, 0, tostring(c) .. " stopped") end
