-- One car around the oval at 800 mm/s; with SLOW = true it takes the first curve pair (17, 18) at
-- 400 mm/s and nothing else differs.
local SLOW = false
local car = pitwall.cars()[1]
local after36 = nil  -- transitions since the car reported piece 36
car.onPosition = function(c, ev)
  if ev.piece == 36 then after36 = 0 end
end
car.onTransition = function(c, ev)
  if after36 == nil then return end
  after36 = after36 + 1
  if after36 == 1 and SLOW then c:setSpeed(400, 20000) end   -- into 17
  if after36 == 3 then c:setSpeed(800, 20000); after36 = nil end  -- into 39
end
car:setSpeed(800, 20000)
pitwall.spawn(function()
  pitwall.sleep(30)
  pitwall.stop()
end)
