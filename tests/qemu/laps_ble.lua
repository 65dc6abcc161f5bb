-- The central of tests/qemu/ble_e2e.sh (PITWALL_QEMU_CENTRAL=pitwall): the one car found over
-- Bluetooth LE, `pitwall emulate-car` behind the real bluetoothd, drives 2 full laps. Any other
-- outcome raises an error, so `pitwall run` exits 1.
--
--   pitwall run tests/qemu/laps_ble.lua --ble --adapter hci1 --duration 30
--
-- A lap ends when position updates go from piece 34 to piece 33 (docs/lua-api.md, "Track
-- pieces"); the first crossing starts lap 1. The wait ends before --duration would end the run
-- with status 0.

local LAPS = 2
local SPEED = 1000 -- mm/s: about 4 s a lap on the oval
local TIMEOUT = 20 -- s

local cars = pitwall.cars()
if #cars ~= 1 then
  error(string.format("expected exactly 1 car over BLE, found %d", #cars))
end
local car = cars[1]
print(string.format("%s: model %s (%d), identifier 0x%08x, at %s", tostring(car), car.model,
  car.modelId, car.identifier, tostring(car.address)))

local laps, lapStart, lastPiece, positions = 0, nil, nil, 0
car.onPosition = function(_, ev)
  positions = positions + 1
  if ev.piece == 33 and lastPiece == 34 then
    if lapStart then
      laps = laps + 1
      print(string.format("%6.2f s  lap %d  %.3f s", ev.time, laps, ev.time - lapStart))
    end
    lapStart = ev.time
  end
  lastPiece = ev.piece
end
car.onDisconnect = function(_, ev)
  if laps < LAPS then pitwall.log("error", "the car disconnected: " .. tostring(ev.reason)) end
end

-- A car whose first connection attempt failed is listed, not connected, and joins later
-- (docs/bluetooth.md): it is driven when it connects.
car.onConnect = function() car:setSpeed(SPEED) end
if car.connected then car:setSpeed(SPEED) end
if not pitwall.waitUntil(function() return laps >= LAPS end, TIMEOUT) then
  error(string.format("%d of %d laps in %d s (%d position updates, last piece %s)", laps, LAPS,
    TIMEOUT, positions, tostring(lastPiece)))
end
car:stop()
print(string.format("%d laps driven over BLE, %d position updates", laps, positions))
pitwall.stop()
