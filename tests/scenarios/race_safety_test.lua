-- Safety: when a car leaves the track, the cars behind it within the safety distance are slowed
-- (ctx.limit, enforced by the director) until it is back; cars ahead of it are not.
-- tags: race errors
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local track = require "pitwall.track"

local speeds = { 900, 500, 1000 }
local cars = {}
for i = 1, 3 do cars[i] = sim.addCar {} end
local A, B, C = cars[1], cars[2], cars[3]
local seenLimit = {}
local Probe = {}
Probe.__index = Probe
function Probe:update(car, ctx)
  if ctx.limit then seenLimit[car] = ctx.limit end
  local v = ctx.limit and math.min(self.speed, ctx.limit) or self.speed
  if car.targetSpeed ~= v then car:setSpeed(v, 2000) end
end

local checked = false
pitwall.spawn(function()
  local s
  pitwall.waitUntil(function() s = race.current; return s and s.green end, 30)
  local a, b = s:entry(A), s:entry(B)
  -- A well ahead of B, 400..900 mm
  expect.truthy(pitwall.waitUntil(function()
    return a.distance and b.distance and a.distance - b.distance > 400 end, 10), "A pulls away")
  local where = sim.truth(A).pieceIndex
  sim.lift(A)
  pitwall.sleep(1)
  expect.eq(b.limit, 300, "B, behind A, is slowed")
  expect.le(B.targetSpeed, 300, "B told to slow down")
  expect.le(sim.truth(B).speed, 300, "B slowed")
  expect.falsy(s:entry(C).limit, "C, ahead of A, is not slowed")
  expect.eq(seenLimit[B], 300, "B's driver saw ctx.limit")
  sim.place(A, where, -68)
  expect.truthy(pitwall.waitUntil(function() return a.loc.localized end, 10), "A found again")
  pitwall.sleep(0.5)
  expect.falsy(b.limit, "B's limit lifted")
  pitwall.sleep(2)
  expect.gt(sim.truth(B).speed, 450, "B back to its speed")
  checked = true
end)

race.laps {
  laps = 3, map = track.fromSim(), results = false, board = false,
  drivers = function(car, i) return setmetatable({ speed = speeds[i] }, Probe) end,
  onLights = function(k, s) race.current = s end,
}
expect.truthy(checked, "the checks ran")
for _, c in ipairs(cars) do expect.eq(sim.truth(c).speed, 0, tostring(c) .. " stopped") end
