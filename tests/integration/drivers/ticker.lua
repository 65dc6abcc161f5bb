-- A driver whose world keeps a timer of its own, printing every second: while its world lives,
-- the log has its ticks (tests/integration/driver_worlds_test.sh: a session's worlds end with it).
local cruiser = require "pitwall.drivers.cruiser"
pitwall.every(1, function() print(string.format("ticker at %.1f", pitwall.now())) end)
return { name = "ticker", new = function() return cruiser.new { speed = 800 } end }
