-- The view's own ghost (tests/integration/ghost_browser_test.sh): car 1 alone at 600 mm/s, no
-- simulated ghost; the standings keep a faster personal best on this track, which the view
-- draws as its ghost and gives car 1's delta against.
local car = pitwall.cars()[1]
car:setSpeed(600, 20000)
pitwall.spawn(function()
  pitwall.sleep(300)
  pitwall.stop()
end)
