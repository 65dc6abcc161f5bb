-- Lap timing on the built-in simulator or on real cars: every car drives at its own speed and
-- lane; each crossing of the finish line prints a lap time.
--
--   build/pitwall run examples/lap_times.lua            -- real time, about 40 s
--   build/pitwall run examples/lap_times.lua --fast     -- the same race in a blink
--   build/pitwall run examples/lap_times.lua --ble      -- real cars (docs/bluetooth.md)
--
-- A lap ends when a car's position updates go from piece 34 to piece 33: the finish line lies
-- between them (docs/lua-api.md, "Track pieces").

local LAPS = tonumber(os.getenv("LAPS")) or 5
local speeds = { 700, 650, 600, 550, 500, 750, 800, 450 }
local lanes = { -68, -23, 23, 68 }

local finished = 0
local cars = pitwall.cars()
print(string.format("%d cars, %d laps each", #cars, LAPS))

for i, car in ipairs(cars) do
  car.laps = 0
  car.best = math.huge
  car.onPosition = function(car, ev)
    if ev.piece == 33 and car.lastPiece == 34 then
      if car.lapStart then
        local lap = ev.time - car.lapStart
        car.laps = car.laps + 1
        local mark = ""
        if lap < car.best then
          car.best = lap
          mark = "  best"
        end
        print(string.format("%6.2f s  %-12s lap %d  %6.3f s%s", ev.time, car.name, car.laps, lap, mark))
        if car.laps == LAPS then
          car:stop()
          finished = finished + 1
          if finished == #cars then pitwall.stop() end
        end
      end
      car.lapStart = ev.time -- the first crossing starts lap 1
    end
    car.lastPiece = ev.piece
  end
  car.onDelocalized = function(car)
    print(string.format("%s left the track", car.name))
  end
  car:setSpeed(speeds[(i - 1) % #speeds + 1], 800)
  car:changeLane(lanes[(i - 1) % #lanes + 1])
end
