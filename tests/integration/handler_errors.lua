-- Played by handler_errors_test.sh: car 2's curve handler misspells setSpeed and fails on every
-- transition, while a timer keeps commanding both cars as a race director would.
local good, bad = pitwall.cars()[1], pitwall.cars()[2]
good:setSpeed(700)
bad:setSpeed(700)
good.onTransition = function(car) car:setSpeed(700) end
bad.onTransition = function(car) car:setSped(700) end
pitwall.every(0.5, function()
  local ok, err = pcall(bad.setSpeed, bad, 900)
  if not ok and not refusedSaid then
    refusedSaid = true
    print("refused: " .. tostring(err))
  end
  good:setSpeed(700)
end)
