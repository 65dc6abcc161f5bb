-- The car behind cannot pass through the car in front on the same lane: it is held behind,
-- both report the collision, and the one in front keeps its lead.
-- tags: sim
local sim = require "pitwall.sim"

local front = sim.addCar { name = "front", lane = 2, piece = 3, distance = 100 }
local back = sim.addCar { name = "back", lane = 2, piece = 2, distance = 100 }
local hits = { front = 0, back = 0 }
front.onCollision = function(car) hits.front = hits.front + 1 end
back.onCollision = function(car) hits.back = hits.back + 1 end

front:setSpeed(400, 25000)
back:setSpeed(900, 25000)
sim.run(20)

local tf, tb = sim.truth(front), sim.truth(back)
expect.ge(tf.collisions, 1, "front car's collisions")
expect.ge(tb.collisions, 1, "back car's collisions")
expect.ge(hits.back, 1, "the rear car reported onCollision")
expect.ge(hits.front, 1, "the front car reported onCollision")
-- Still in the same order: the car behind is behind (or level within a car length).
local lap = sim.track().lapLength
local function along(t) return t.laps * lap + t.lapDistance end
expect.lt(along(tb), along(tf), "the rear car stays behind")
expect.near(tb.speed, tf.speed, 50, "held at the speed of the car in front")

-- In another lane it may pass.
back:changeLane(68)
sim.run(15)
expect.gt(along(sim.truth(back)), along(sim.truth(front)), "passes in the other lane")
