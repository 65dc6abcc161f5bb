-- A remote car bridged by the seed's controller (mqtt_seed_remote_test.sh drives this against
-- tests/integration/fake_controller.py): what a script sees of it and what reaches it. Prints
-- one "check NAME VALUE…" line per step; the test reads them.
local function check(name, ...)
  local values = { name }
  for i = 1, select("#", ...) do values[#values + 1] = tostring((select(i, ...))) end
  print("check " .. table.concat(values, " "))
end
local car = pitwall.cars()[1]
check("car", tostring(car), car.model, car.address)
local positions, pinged, battery = 0, false, nil
car.onPosition = function(_, ev) positions = positions + 1 end
car.onPing = function() pinged = true end
car.onBattery = function(_, ev) battery = ev.millivolts end

pitwall.spawn(function()
  car:setSpeed(600, 2000)
  check("speed", pitwall.waitUntil(function() return car.speed >= 550 end, 10), car.speed)
  car:changeLane(23)
  check("lane", pitwall.waitUntil(function() return math.abs(car.offset - 23) < 2 end, 10),
    car.offset)
  car:ping()
  car:battery()
  car:version()
  check("ping", pitwall.waitUntil(function() return pinged end, 5))
  check("battery", pitwall.waitUntil(function() return battery ~= nil end, 5), battery)
  check("version", pitwall.waitUntil(function() return car.firmware ~= nil end, 5),
    car.firmware)
  check("positions", positions > 0 and car.piece ~= nil, positions, car.piece)
  car:uturn()
  check("uturn", pitwall.waitUntil(function() return math.abs(car.offset + 23) < 2 end, 5),
    car.offset)
  -- the controller has no intent for the lights: refused here with the reason, not lost there
  local ok, err = pcall(car.lights, car, 0x44)
  check("lights", ok, err)
  car:stop()
  check("stopped", pitwall.waitUntil(function() return car.speed == 0 end, 10), car.speed)
  pitwall.stop()
end)
