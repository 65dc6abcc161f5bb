-- Your car's driver. The race calls update(car, ctx) ten times a second while your car drives.
--   car:setSpeed(speed, accel)    mm/s (a car goes 300 to 1500), mm/s² (how hard)
--   car:changeLane(offset)        mm from the middle of the road: -68 left … 68 right
--   car.speed, car.offset, car.piece   what your car reports
--   ctx:ahead()                   the nearest car ahead ({car, gap}, gap in mm) or nil
-- Save to race it; Test to try it alone on the simulator first.
local drivers = require "pitwall.drivers"

local driver = { speed = 700 }

function driver:update(car, ctx)
  local speed = self.speed
  local near = ctx:ahead()
  if near and near.gap < 250 then speed = 400 end -- do not run into the car ahead
  drivers.setSpeed(car, drivers.cap(ctx, speed), 2000)
end

return driver
