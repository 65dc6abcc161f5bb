-- Links that drop as on a real evening (issue 36): the scan car's link drops mid-scan, and later
-- every car's link drops at once (bluetoothd restarting does that). The scan goes on where it
-- was once its car is back (a car stops when its link drops: no piece is lost), the race waits
-- for cars that are away instead of ending because none is connected, and every car finishes.
-- A car that does not come back within reconnectTimeout is out, and the race ends without it.
-- tags: race sim
local sim = require "pitwall.sim"
local race = require "pitwall.race"

local cars = {}
for k = 1, 3 do cars[k] = sim.addCar {} end

-- the scan car resets 4 s into its scan lap, and can be reached again 2 s later
local scanDropped
pitwall.after(4, function()
  scanDropped = pitwall.now()
  sim.reboot(cars[1], 2)
end)

local allDown
local r = race.laps {
  laps = 4,
  scan = true,
  board = false,
  drivers = function() return race.Steady.new { speed = 700 } end,
  onLap = function(car, lap)
    if car == cars[1] and lap.number == 2 and not allDown then
      allDown = pitwall.now()
      for _, c in ipairs(cars) do sim.reboot(c, 3) end
    end
  end,
}
expect.truthy(scanDropped, "the scan car's link dropped during its scan lap")
expect.eq(r.map:layout(), "start S L L S S L L", "and the scan still learnt the oval")
expect.truthy(allDown, "every car's link dropped at once mid-race")
for _, row in ipairs(r:results()) do
  expect.eq(row.status, "finished", row.car .. " finished")
  expect.eq(row.laps, 4, row.car .. " drove its 4 laps")
end
-- car.link tells the story: the scan car dropped twice, the others once, each came back
for k, c in ipairs(cars) do
  local link = c.link
  expect.eq(link.drops, k == 1 and 2 or 1, c.name .. ": its drops in car.link")
  expect.eq(link.connects, link.drops + 1, c.name .. ": connected again after each")
  expect.truthy(type(link.lastDrop) == "string" and #link.lastDrop > 0, c.name .. ": why")
end

-- A car that stays away longer than reconnectTimeout is out; the others finish
local out = cars[3]
local r2 = race.laps {
  laps = 3,
  board = false,
  reconnectTimeout = 10,
  drivers = function() return race.Steady.new { speed = 700 } end,
  onLap = function(car, lap)
    if car == out and lap.number == 1 then sim.reboot(out, 600) end
  end,
}
local status = {}
for _, row in ipairs(r2:results()) do status[row.car] = row.status end
expect.eq(status[out.name], "DNF (disconnected)", "the car that never came back is out")
expect.eq(status[cars[1].name], "finished", "the others finished")
expect.eq(status[cars[2].name], "finished", "the others finished")
