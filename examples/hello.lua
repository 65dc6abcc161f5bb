-- The README's first script: print what the cars report, change a lane, stop after 10 s.
--
--   build/pitwall run examples/hello.lua --cars 2

for i, car in ipairs(pitwall.cars()) do
  car.onPosition = function(car, ev)
    print(car.name, ev.piece, ev.location, ev.speed)
  end
  car:setSpeed(500 + 100 * i, 1000)          -- mm/s, mm/s²
end
pitwall.spawn(function()
  pitwall.sleep(5)
  pitwall.cars()[1]:changeLane(68)            -- offset from the road centre, mm
  pitwall.sleep(5)
  pitwall.stop()                              -- stops the cars, ends the run
end)
