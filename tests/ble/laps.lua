-- Drives every car over Bluetooth LE until each has crossed the finish line CROSSINGS times
-- (default 2: at least one whole lap), then prints one summary line per car and stops.
-- Used by tests/integration/ble_*_test.sh against the fake BlueZ, and by tests/qemu against the
-- real bluetoothd. Fails (exit 1) when the cars do not get there within TIMEOUT seconds.
local crossings = tonumber(os.getenv("CROSSINGS") or "2")
local speed = tonumber(os.getenv("SPEED") or "1000")
local timeout = tonumber(os.getenv("TIMEOUT") or "30")
-- MUST: the addresses (comma-separated) of the cars that must lap; default: every car
local must = nil
if os.getenv("MUST") then
  must = {}
  for a in os.getenv("MUST"):gmatch("[^,]+") do must["ble:" .. a] = true end
end

local stats = {}

local function watch(car)
  if stats[car] then return end
  local s = { laps = 0, positions = 0, connects = 0, disconnects = 0, malformed = 0,
              refusedWhileDown = 0, last = nil }
  stats[car] = s
  car.onPosition = function(c, ev)
    s.positions = s.positions + 1
    if ev.piece == 33 and s.last == 34 then s.laps = s.laps + 1 end
    s.last = ev.piece
  end
  car.onConnect = function(c)
    s.connects = s.connects + 1
    s.last = nil
    c:setSpeed(speed, 5000)  -- a car that lost its link stopped: drive on
  end
  car.onDisconnect = function(c, ev)
    s.disconnects = s.disconnects + 1
    s.lastReason = ev.reason
    -- a command while the car is away fails with a clear error and sends nothing
    local ok, err = pcall(c.setSpeed, c, 500)
    if not ok and tostring(err):find("not connected") then
      s.refusedWhileDown = s.refusedWhileDown + 1
    else
      pitwall.log("error", "a command to a disconnected car did not fail: " .. tostring(err))
    end
  end
  car.onMalformed = function(c, ev)
    s.malformed = s.malformed + 1
  end
  if car.connected then car:setSpeed(speed, 5000) end
end

for _, car in ipairs(pitwall.cars()) do watch(car) end
pitwall.onCar = function(car)
  watch(car)
  stats[car].connects = stats[car].connects + 1
  car:setSpeed(speed, 5000)
end

local function done()
  for _, car in ipairs(pitwall.cars()) do
    if must == nil or must[car.address] then
      local s = stats[car]
      if not s or s.laps < crossings then return false end
    end
  end
  return true
end

local ok = pitwall.waitUntil(done, timeout)
local cars = pitwall.cars()
table.sort(cars, function(a, b) return a.address < b.address end)
for _, car in ipairs(cars) do
  local s = stats[car]
  print(string.format(
    "car %s %s model=%s laps=%d positions=%d connects=%d disconnects=%d malformed=%d refusedWhileDown=%d connected=%s",
    car.address, car.name, car.model, s.laps, s.positions, s.connects, s.disconnects, s.malformed,
    s.refusedWhileDown, tostring(car.connected)))
end
if not ok then error("the cars did not complete " .. crossings .. " finish-line crossings in " .. timeout .. " s") end
pitwall.stop()
