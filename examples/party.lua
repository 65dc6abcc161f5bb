-- A party race: people against AI drivers, with items. Every lap a car completes earns it an
-- item, used at once: a BOOST (its own top speed up a quarter for 3 s) or OIL (the car just
-- ahead of it, any lane, slowed to 400 mm/s for 2.5 s). The view's event log shows every item.
--
--   build/pitwall run examples/party.lua --humans 2 --view --cars 4   -- two phones, two AI
--     then open the view's /drive page on each phone (the URL is printed) and take a seat
--   build/pitwall run examples/party.lua --humans 1 --keyboard         -- you, on the arrow keys
--   build/pitwall run examples/party.lua --humans 2 --gamepads --view  -- two gamepads
--   build/pitwall run examples/party.lua --ble --humans 2 --view       -- the same, real cars
--
-- Seats still free after WAIT seconds (default 60) get an AI driver; without --humans every car
-- is an AI (then it is a plain grand prix with items). LAPS laps (default 5). With --view the
-- results stay up for SHOW seconds (default 60) before the run ends.
local race = require "pitwall.race"
local drivers = require "pitwall.drivers"

local LAPS = tonumber(os.getenv("LAPS")) or 5
local WAIT = tonumber(os.getenv("WAIT")) or 60
local AI = { { "overtaker", { speed = 950 } }, { "follower", { speed = 1000 } },
  { "cruiser", { speed = 900 } }, { "lanekeeper", { speed = 950 } } }

local cars = pitwall.cars()
local seats = pitwall.seats()

-- The players: wait until every seat is held, or WAIT s.
if #seats > 0 then
  print(string.format("Party: %d seat(s) for people; waiting up to %d s for the players "
    .. "(phones: the view's /drive page)", #seats, WAIT))
  pitwall.waitUntil(function()
    for _, seat in ipairs(seats) do if not seat.held then return false end end
    return true
  end, WAIT, 0.1)
  for _, seat in ipairs(seats) do
    print(string.format("  seat %d: %s", seat.number,
      seat.held and (seat.player or seat.holder) or "free: an AI drives car " .. seat.number))
  end
end

-- ---- the items ----
local slowUntil, boostUntil = {}, {} -- car → engine time the item wears off

local function say(text)
  print(text)
  pitwall.view.event(text)
end

local function itemFor(car, session)
  local e = session:entry(car)
  if math.random() < 0.5 then
    boostUntil[car] = pitwall.now() + 3
    say(string.format("%s: BOOST for 3 s", car.name))
    return
  end
  local ahead = e.ctx and e.ctx:ahead()
  if ahead and ahead.gap < 1500 then
    slowUntil[ahead.car] = pitwall.now() + 2.5
    say(string.format("%s drops OIL: %s slowed for 2.5 s", car.name, ahead.car.name))
  else
    say(string.format("%s drops OIL, but nobody is close ahead", car.name))
  end
end

-- Any driver with the items on top: oil caps the speed (ctx.limit, which every driver obeys);
-- a boost raises the driver's own top speed (`max` of a human, `speed` of an AI).
local function withItems(inner)
  local d = { name = inner.name, seat = rawget(inner, "seat") } -- (the view shows both)
  local key = rawget(inner, "max") and "max" or "speed"
  local base = inner[key]
  local function drive(method, car, ctx)
    if not inner[method] then return end
    local limit = ctx.limit
    if (slowUntil[car] or 0) > pitwall.now() then ctx.limit = math.min(limit or math.huge, 400) end
    if base then
      inner[key] = (boostUntil[car] or 0) > pitwall.now() and math.min(1500, base * 1.25) or base
    end
    inner[method](inner, car, ctx)
    ctx.limit = limit
  end
  function d.update(_, car, ctx) drive("update", car, ctx) end
  if inner.waiting then function d.waiting(_, car, ctx) drive("waiting", car, ctx) end end
  if inner.start then function d.start(_, car, ctx) inner:start(car, ctx) end end
  if inner.finish then function d.finish(_, car, ctx) inner:finish(car, ctx) end end
  return d
end

local function driverFor(car, i)
  local seat = seats[i]
  if seat and seat.held then
    return withItems(drivers.load("human").new { seat = seat, max = 1200, assist = false })
  end
  local pick = AI[(i - 1) % #AI + 1]
  return withItems(drivers.load(pick[1]).new(pick[2]))
end

print(string.format("Party race: %d cars, %d laps", #cars, LAPS))
local party = race.laps {
  laps = LAPS, -- (the map: the simulator's own, or a scan lap on real cars)
  drivers = driverFor,
  title = string.format("Party race, %d laps", LAPS),
  onLap = function(car, lap, session)
    if not session:entry(car).finished then itemFor(car, session) end
  end,
}
print(race.winner(party) or "No winner: nobody finished")
if pitwall.view.active then -- the results stay up on the view and the phones for a while
  local show = tonumber(os.getenv("SHOW")) or 60
  print(string.format("The results stay on the view for %d s (Ctrl-C ends sooner)", show))
  pitwall.sleep(show)
end
pitwall.stop()
