-- The central of tests/qemu/ble_e2e.sh's `links` check: the one car found over Bluetooth LE
-- (`pitwall emulate-car` behind the real bluetoothd) driven at 600 mm/s while the guest powers
-- the central's controller off and on and restarts bluetoothd. Prints "driving" once the car
-- reports driving, "down REASON" at each drop, and "back N after S s" when, after its Nth drop,
-- the car reports driving again (its first position update after the reconnection: connected,
-- SDK mode again, the speed sent again). Runs until Ctrl-C or --duration.
local SPEED = 600

local cars = pitwall.cars()
if #cars ~= 1 then error(string.format("expected exactly 1 car over BLE, found %d", #cars)) end
local car = cars[1]
local drops, downAt, away, driving = 0, nil, false, false

car.onDisconnect = function(_, ev)
  drops = drops + 1
  downAt, away = pitwall.now(), true
  print(string.format("down %s", tostring(ev.reason)))
end
-- a driver drives a car that comes back (the engine sent SDK mode again; the speed is ours)
car.onConnect = function() car:setSpeed(SPEED) end
car.onPosition = function()
  if away then
    away = false
    print(string.format("back %d after %.1f s (connects=%d drops=%d)", drops, pitwall.now() - downAt,
      car.link.connects, car.link.drops))
  elseif not driving then
    driving = true
    print("driving")
  end
end

-- A car whose first connection attempt failed is listed, not connected, and joins later
-- (docs/bluetooth.md): onConnect drives it then.
if car.connected then car:setSpeed(SPEED) end
pitwall.sleep(3600)
