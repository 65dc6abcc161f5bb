-- The reference for a broken save: a new version that stops its car as it loads and commands
-- nothing after (the commands to the other cars are refused, hence the pcall).
for _, car in ipairs(pitwall.cars()) do pcall(car.stop, car) end
return { update = function() end }
