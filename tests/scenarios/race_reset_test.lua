-- A car that resets mid-race, as one does on a tired cell under hard acceleration (issue 34): a
-- second into its second lap its connection drops, it stands where it is with everything
-- forgotten (SDK mode off, speed 0) and can be reached again 3 s later. The link connects it
-- again, SDK mode is sent again, its driver drives it again, its tracker finds it on the track
-- (it was lost on the drop), and it finishes the race with its laps: the lap it reset in is slow,
-- the others as before. The other cars race on meanwhile.
-- tags: race sim
local sim = require "pitwall.sim"
local race = require "pitwall.race"

local cars = {}
for k = 1, 3 do cars[k] = sim.addCar {} end
local victim = cars[2]
local dropped, back
victim.onDisconnect = function() dropped = pitwall.now() end
victim.onConnect = nil
pitwall.listen(victim, "onStatus", function()
  if dropped and not back and victim.connected then back = pitwall.now() end
end)

local resetAt
local r = race.laps {
  laps = 4,
  board = false,
  drivers = function() return race.Steady.new { speed = 700 } end,
  onLap = function(car, lap)
    if car == victim and lap.number == 1 then
      pitwall.after(1, function()
        resetAt = pitwall.now()
        sim.reboot(victim, 3)
      end)
    end
  end,
}
local rows = {}
for _, row in ipairs(r:results()) do rows[row.car] = row end

expect.truthy(resetAt, "the car reset mid-race")
expect.truthy(dropped and dropped >= resetAt, "its connection dropped")
expect.truthy(back and back >= resetAt + 3, "and came back once it could be reached (3 s)")
expect.truthy(sim.truth(victim).sdkMode, "in SDK mode again")
local row = rows[victim.name]
expect.eq(row.laps, 4, "it finished its 4 laps")
expect.truthy(row.finished, "and took the flag")
local e = r:entry(victim)
local slowest, others = 0, math.huge
for k = 1, 4 do
  local t = e.timer.history[k].time
  if k == 2 then slowest = t else others = math.min(others, t) end
end
expect.gt(slowest, others + 3, "the lap it reset in lost the time it stood")
for _, car in ipairs { cars[1], cars[3] } do
  expect.eq(rows[car.name].laps, 4, car.name .. " raced on and finished")
end
