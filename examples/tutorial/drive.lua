-- Tutorial step 1 (docs/tutorial.md): make a car drive, and print what it reports.
--
--   build/pitwall run examples/tutorial/drive.lua --cars 1

local car = pitwall.cars()[1]
print("driving " .. tostring(car))

car.onPosition = function(car, ev)
  print(string.format("%5.2f s  piece %2d  location %2d  %4d mm/s", ev.time, ev.piece, ev.location, ev.speed))
end

car:setSpeed(600)     -- mm/s
pitwall.sleep(5)      -- seconds; the main chunk may wait
car:stop()
pitwall.sleep(1)
pitwall.stop()        -- ends the run (and stops every car)
