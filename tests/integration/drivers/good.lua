-- A student's driver, as a class: a cruiser at 800 mm/s (the shipped library is there to use).
local cruiser = require "pitwall.drivers.cruiser"
local Good = { name = "good" }
function Good.new() return cruiser.new { speed = 800 } end
return Good
