-- The marshal (docs/racing.md "What a session does"): a driver that stands its car in lane +23
-- halfway through the race, and one that drives into it from behind and keeps pushing. Held in
-- the contact, neither moves again by itself. The marshal sees both laps taking far longer than
-- the field's best, says so (onSlowLap, a warning in the log and the view's event log), drives
-- the stuck cars at 300 mm/s for 2 s and sends the pusher to a free lane: it finishes the race.
-- A cruiser, which starts in lane +23 and runs into the stubborn car a lap later, is freed the
-- same way and finishes too; the stubborn car, driven a little each time it is seen, is
-- reported again and again, each time slower.
-- tags: race
local sim = require "pitwall.sim"
local race = require "pitwall.race"

local cars = {}
for k = 1, 3 do cars[k] = sim.addCar {} end

-- into lane +23 once rolling
local function toLane(self, car)
  if not self.laned and (car.speed or 0) > 200 then self.laned = true car:changeLane(23) end
end
-- stands for good once it has driven 3 s
local Stubborn = { name = "stubborn" }
function Stubborn:start() self.from = pitwall.now() end
function Stubborn:update(car)
  local v = pitwall.now() - self.from < 3 and 600 or 0
  if car.targetSpeed ~= v then car:setSpeed(v, 2000) end
  toLane(self, car)
end
-- drives at 900 in lane +23 whatever is in front of it
local Pusher = { name = "pusher" }
function Pusher:update(car)
  if car.targetSpeed ~= 900 then car:setSpeed(900, 2000) end
  toLane(self, car)
end

local slow = {}
local r = race.laps {
  laps = 3,
  board = false,
  drivers = function(_, i)
    if i == 1 then return setmetatable({}, { __index = Stubborn }) end
    if i == 2 then return setmetatable({}, { __index = Pusher }) end
    return "cruiser"
  end,
  onSlowLap = function(car, info)
    slow[#slow + 1] = { car = car, info = info }
  end,
  finishTimeout = 40,
}
local rows = {}
for _, row in ipairs(r:results()) do rows[row.car] = row end

local function reportsOf(car)
  local out = {}
  for _, s in ipairs(slow) do if s.car == car then out[#out + 1] = s.info end end
  return out
end
local pusher, stubborn, cruiser = reportsOf(cars[2]), reportsOf(cars[1]), reportsOf(cars[3])
expect.gt(#pusher, 0, "the pusher's slow lap was seen")
expect.gt(#stubborn, 0, "the stubborn car's slow lap was seen")
expect.truthy(pusher[1].action:find("stuck in a contact", 1, true), pusher[1].action)
expect.truthy(pusher[1].action:find("to lane", 1, true), "the pusher sent to a free lane: "
  .. pusher[1].action)
expect.gt(pusher[1].took, 2.5 * pusher[1].reference, "slow: over 2.5 times the reference")
expect.eq(rows[cars[2].name].laps, 3, "the pusher, freed, finished its three laps")
expect.truthy(rows[cars[2].name].finished, "the pusher finished")
for _, info in ipairs(cruiser) do
  expect.truthy(info.action:find("stuck in a contact", 1, true), "the cruiser: " .. info.action)
end
expect.eq(rows[cars[3].name].laps, 3, "the cruiser finished its three laps")
expect.gt(#stubborn, 1, "the stubborn car reported again while it stays slow")
for k = 2, #stubborn do
  expect.gt(stubborn[k].took, stubborn[k - 1].took, "each report of a longer lap")
end
