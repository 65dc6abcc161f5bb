-- The view's ghost (tests/integration/ghost_browser_test.sh): the ghost of even.jsonl's best lap
-- (in the current folder) beside car 1 at 600 mm/s, which is slower: its delta rises.
local sim = require "pitwall.sim"
local ghost = sim.addGhost { record = "even.jsonl" }
local car = pitwall.cars()[1]
car:setSpeed(600, 20000)
ghost:setSpeed(600, 20000)
pitwall.spawn(function()
  pitwall.sleep(300)
  pitwall.stop()
end)
