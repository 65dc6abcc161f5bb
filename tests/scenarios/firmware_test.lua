-- Firmware families (docs/simulator.md "Firmware families"): cars of firmware 0x266e send the
-- older layouts — the 19-byte transition update and a speed update that says the desired speed
-- only — and race beside newer cars with their laps, order, gaps and stops as the ground truth
-- says (race_truth.lua), under the real model.
-- tags: race
local sim = require "pitwall.sim"
sim.sensor { model = "real" }

local speedEvents, withActual, withAccel = {}, {}, {}
local r = require "race_truth"(4, { { firmware = 0x266e }, {}, { firmware = 0x266e },
  { firmware = 0x2b70 } }, function(cars)
  -- what the cars answer is what a script reads
  pitwall.sleep(0.5)
  expect.eq(cars[1].firmware, 0x266e, "car 1's firmware")
  expect.eq(cars[2].firmware, 0x2b70, "car 2's firmware: the default")
  expect.eq(cars[3].firmware, 0x266e, "car 3's firmware")
  for i, c in ipairs(cars) do
    speedEvents[i], withActual[i], withAccel[i] = 0, 0, 0
    c.onSpeed = function(_, ev)
      speedEvents[i] = speedEvents[i] + 1
      if ev.actual then withActual[i] = withActual[i] + 1 end
      if ev.accel then withAccel[i] = withAccel[i] + 1 end
    end
  end
end)
for i, c in ipairs(r.cars) do
  expect.ge(speedEvents[i], 1, "car " .. i .. " sent speed updates")
  local older = c.firmware == 0x266e
  -- the older firmware's speed update says the desired speed only
  expect.eq(withActual[i], older and 0 or speedEvents[i], "car " .. i .. ": updates with actual")
  expect.eq(withAccel[i], older and 0 or speedEvents[i], "car " .. i .. ": updates with accel")
end

-- a firmware that is not a version is refused with a sentence
for _, bad in ipairs { 0, -1, 0x10000, 1.5, "2b70x", true } do
  local ok, err = pcall(sim.addCar, { firmware = bad, piece = 2, lane = 1 })
  expect.falsy(ok, "firmware " .. tostring(bad) .. " refused")
  expect.truthy(tostring(err):find("firmware", 1, true), "the sentence names the option: " .. tostring(err))
end
