-- pitwall.drivers.human: a person drives, from a seat (docs/racing.md "Human drivers").
--
--   human.new{seat = 1, max = 1200, min = 300, accel = 2500, decel = 4000, assist = false}
--
-- The seat (pitwall.seat(n), or its number) is held by a phone on the view's /drive page, a
-- gamepad, the terminal's keyboard, or a script (seat:feed). Its throttle 0..1 maps to the car's
-- speed: 0 stops, anything above maps linearly onto min..max mm/s, always under the race's limit
-- (ctx.limit: a safety car, a penalty). Lane steps move the car one lane left or right of the one
-- it is in (a car that stands cannot change lanes: a step asked then is dropped). A seat without
-- input (its phone silent for 1 s, gone, or unplugged) reads throttle 0: the engine has slowed the
-- car already (while a driver drives from the seat: seat:driving(), said at every update), and the
-- driver asks for 0 as well. Seat k drives car k: a human driver given another car's seat raises.
-- `assist` caps the speed in curves at what the cruiser would drive there (a car too fast in a
-- curve comes off the track, as on the real one).
--
-- During the start lights the director calls driver:waiting: a human who gives throttle before
-- green jumps the start, and is caught like anyone else.
local drivers = require "pitwall.drivers"
local localize = require "pitwall.localize"

local human = { name = "human" }
local Human = {}
Human.__index = Human
Human.__name = "human driver" -- (how errors name it: "human driver has no method …")

human.options = { "seat", "max", "min", "accel", "decel", "assist" }

local LANES = { -68, -23, 23, 68 }

local function checkSpeed(name, v, lo, hi)
  if v ~= nil and (type(v) ~= "number" or v ~= v or v < lo or v > hi) then
    pitwall._raise(string.format("human.new: %s must be a number from %d to %d mm/s, got %s",
      name, lo, hi, tostring(v)))
  end
end

function human.new(options)
  options = options or {}
  pitwall._checkOptionsOf("human.new", options, human.options)
  local seat = options.seat
  if type(seat) == "number" then
    local found = pitwall.seat(seat)
    if not found then
      local n = #pitwall.seats()
      pitwall._raise(string.format("human.new: there is no seat %s: %s", tostring(seat),
        n == 0 and "this run has no seats (start it with --humans N, or sim.openSeats(n) in a "
          .. "scenario)" or ("this run has seats 1.." .. n)))
    end
    seat = found
  elseif seat == nil or type(seat) ~= "userdata" then
    pitwall._raise("human.new: give the seat the person drives from: seat = 1 (a number) or "
      .. "seat = pitwall.seat(1), got " .. tostring(seat))
  end
  checkSpeed("max", options.max, 100, 1500)
  checkSpeed("min", options.min, 0, 1500)
  for _, k in ipairs { "accel", "decel" } do
    local v = options[k]
    if v ~= nil and (type(v) ~= "number" or v ~= v or v < 100 or v > 25000) then
      pitwall._raise(string.format("human.new: %s must be a number from 100 to 25000 mm/s², got %s",
        k, tostring(v)))
    end
  end
  local self = setmetatable({
    name = "human",
    seat = seat,
    max = options.max or 1200,
    min = options.min or 300,
    accel = options.accel or 2500,
    decel = options.decel or 4000,
    assist = options.assist or false,
  }, Human)
  if self.min > self.max then
    pitwall._raise(string.format("human.new: min (%d) is above max (%d)", self.min, self.max))
  end
  if self.assist then self.cruiser = drivers.load("cruiser").new { speed = self.max } end
  return self
end

--- The speed the seat asks for now (mm/s), under the race's limit.
function Human:target(car, ctx)
  local t = self.seat.throttle
  if t < 0.02 then return 0 end
  local v = self.min + (self.max - self.min) * math.min(t, 1)
  if self.cruiser then v = math.min(v, (self.cruiser:target(car, ctx))) end
  return drivers.cap(ctx, v)
end

-- The seat drives `car`: seat k drives car k (its loss stops car k).
function Human:_check(car)
  local mine = self.seat.car
  if mine ~= car then
    pitwall._raise(string.format("human driver: seat %d drives %s, not %s: give this car's seat "
      .. "(seat = %s)", self.seat.number, tostring(mine), tostring(car), tostring(car.number)))
  end
end

function Human:_drive(car, ctx)
  local v = self:target(car, ctx)
  local accel = v < (car.targetSpeed or 0) and self.decel or self.accel
  drivers.setSpeed(car, v, accel)
end

function Human:_lanes(car)
  local steps = self.seat:lanes()
  if steps == 0 or drivers.changing(car) then return end
  if (car.targetSpeed or 0) <= 0 or not drivers.moving(car) then return end -- dropped
  local here = localize.nearestLane(car.targetOffset or car.offset or 0)
  local k = 1
  for i, lane in ipairs(LANES) do if lane == here then k = i end end
  k = math.max(1, math.min(#LANES, k + steps))
  if LANES[k] ~= here then car:changeLane(LANES[k]) end
end

function Human:update(car, ctx)
  self:_check(car)
  self:_drive(car, ctx)
  self:_lanes(car)
  self.seat:driving() -- the engine stops the car if the seat's holder goes (seats.hpp)
end

-- The lights are on: the throttle goes through, so a person who does not wait jumps the start.
function Human:waiting(car, ctx)
  self:_check(car)
  if self.seat.throttle >= 0.02 then self:_drive(car, ctx) end
  self.seat:lanes() -- (a step asked on the grid is not kept for the green light)
  self.seat:driving()
end

return human
