-- Write your own driver: a table with update(car, ctx), called every ctx.period s while the car
-- races (start and finish are optional). This one drives fast on straights, slows before curves,
-- keeps its distance to the car ahead, and always respects ctx.limit (the director's safety cap).
-- Run it with --watch and edit `fast` or `slow` while it races: the race goes on, and the new
-- driver takes over what the old one counted (handover / takeover, docs/racing.md).
--
--   build/pitwall run examples/custom_driver.lua --fast
--   build/pitwall run examples/custom_driver.lua --watch
local race = require "pitwall.race"

local Careful = { name = "careful" }
Careful.__index = Careful

function Careful.new(options)
  return setmetatable({ fast = options.fast or 1100, slow = options.slow or 650, held = 0 },
    Careful)
end

function Careful:start(car, ctx)
  pitwall.log("info", tostring(car) .. ": green, on " .. tostring(ctx.map))
end

function Careful:update(car, ctx)
  local speed = self.fast
  for _, piece in ipairs(ctx:upcoming(300)) do -- the next 300 mm of track
    if piece.type == "curve" then speed = self.slow end
  end
  local ahead = ctx:ahead()
  if ahead and ahead.gap < 250 and math.abs((ahead.lane or 0) - (car.offset or 0)) < 40 then
    speed = math.min(speed, ahead.car.speed or speed) -- do not ram the car in front
    self.held = self.held + 1
  end
  if ctx.limit then speed = math.min(speed, ctx.limit) end
  if car.targetSpeed ~= speed then car:setSpeed(speed, 2000) end -- only what changes
end

function Careful:finish(car, ctx)
  pitwall.log("info", string.format("%s: done, cooling down (held up for %.1f s)", tostring(car),
    self.held * ctx.period))
end

-- A save of the script (--watch) makes a new driver mid-race: hand it what this one counted.
function Careful:handover()
  return { held = self.held }
end

function Careful:takeover(car, ctx, state, from)
  if from == "careful" and state then self.held = state.held end
end

local LAPS = tonumber(os.getenv("LAPS")) or 3
local drivers = {}
for i, car in ipairs(pitwall.cars()) do
  -- car 1 drives the custom driver; the others hold a steady speed to race against
  drivers[car] = i == 1 and Careful.new {} or race.Steady.new { speed = 600 + 50 * i }
end
race.laps { laps = LAPS, drivers = drivers, title = "Custom driver" }
pitwall.stop()
