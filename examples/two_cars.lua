-- Two cars and lane changes: the faster car swaps to the other side of the road every few
-- seconds while the slower one keeps its lane.
--
--   build/pitwall run examples/two_cars.lua --cars 2

local cars = pitwall.cars()
assert(#cars >= 2, "this example needs two cars: run it with --cars 2")
local fast, slow = cars[1], cars[2]

for _, car in ipairs({ fast, slow }) do
  car.onOffset = function(car, ev)
    print(string.format("%6.2f s  %-12s now at %+.0f mm", ev.time, car.name, ev.offset))
  end
  car.onDelocalized = function(car) print(car.name .. " left the track") end
end

-- A lane change needs a moving car (docs/lua-api.md): speed first, then the lane.
slow:setSpeed(450)
slow:changeLane(-23)
fast:setSpeed(750)
fast:changeLane(-68)

pitwall.spawn(function()
  local side = 68
  for _ = 1, 6 do
    pitwall.sleep(3)
    print(string.format("%6.2f s  %-12s changes lane to %+d mm", pitwall.now(), fast.name, side))
    fast:changeLane(side, 400, 4000)
    side = -side
  end
  pitwall.sleep(2)
  pitwall.stop()
end)
