-- A race of two cars with the ghost --ghost gave (tests/integration/ghost_run_test.sh): says
-- whether the ghost moved before the green light, how many entries the race had, and whether the
-- ghost stands once the race is over.
local race = require "pitwall.race"
local simulated, sim = pcall(require, "pitwall.sim") -- (with --ble: what the ghost reports)
local function speed(car) return simulated and sim.truth(car).speed or car.speed or 0 end
local function laps(car) return simulated and sim.truth(car).laps or "?" end
local ghost
for _, c in ipairs(pitwall.cars()) do
  if c.ghost then ghost = c end
end
assert(ghost, "no ghost among the cars")
local r = race.new { laps = tonumber(os.getenv("GHOST_LAPS") or "4"), drivers = "cruiser" }
local movedEarly = false
pitwall.spawn(function()
  while not r.green do
    if speed(ghost) > 0 then movedEarly = true end
    pitwall.sleep(0.02)
  end
end)
r:run()
pitwall.sleep(1)
print("entries:", #r.order, "ghost moved before green:", movedEarly, "ghost laps:", laps(ghost),
  "ghost speed after:", simulated and speed(ghost) or ghost.targetSpeed)
pitwall.stop()
