-- A contact in a race is in the log and the view's event log, naming who ran into whom (docs/racing.md
-- "What a session does"): a fast car that moves into the lane of a slow one runs into it.
-- Reports with no car near (a real car sends them at many boundaries at speed) are not.
-- tags: race
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local track = require "pitwall.track"
local drivers = require "pitwall.drivers"

local slow, fast = sim.addCar {}, sim.addCar {}
local events = {}
-- (how far apart the cars truly were when a contact was said)
local apart = {}
pitwall.view.event = function(text)
  events[#events + 1] = text
  local lap = sim.track().lapLength
  local d = math.abs(sim.truth(fast).lapDistance - sim.truth(slow).lapDistance) % lap
  apart[#events] = math.min(d, lap - d)
end

local rammer = { name = "rammer" }
function rammer.update(_, car, ctx)
  if car.targetSpeed ~= 1100 then car:setSpeed(1100, 2000) end
  if math.abs((car.offset or 0) - (slow.offset or 0)) > 20 and drivers.moving(car) then
    pcall(car.changeLane, car, slow.offset)
  end
end

race.laps { laps = 3, map = track.fromSim(), board = false, results = false, finishTimeout = 5,
  drivers = function(car) return car == slow and race.Steady.new { speed = 400 } or rammer end }

local contacts = 0
local names = { [fast.name .. " ran into " .. slow.name] = true, [slow.name .. " ran into " .. fast.name] = true,
  [fast.name .. " and " .. slow.name] = true, [slow.name .. " and " .. fast.name] = true }
for k, text in ipairs(events) do
  if text:find("^contact: ") then
    contacts = contacts + 1
    expect.truthy(names[text:sub(10)], "both cars named: " .. text)
    expect.le(apart[k], 250, "said while the cars were touching: " .. text)
  end
end
expect.ge(sim.truth(fast).collisions, 1, "the fast car did run into the slow one")
expect.ge(contacts, 1, "the contact is in the view's event log")
