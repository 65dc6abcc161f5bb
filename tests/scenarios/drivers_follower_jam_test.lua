-- The jam of a starved real-time grand prix (issue 34, docs/racing.md "follower"): a follower
-- takes the car it followed, reckoned a little behind it in its lane, for still just ahead (a
-- reckoning error, cars in one lane cannot pass). When that car really is behind it — the
-- follower came into the lane ahead of it — the follower stood for it, and it, unable to pass,
-- stood behind the follower: both crawled for the rest of the race. The belief lasts 2 s now.
-- tags: drivers
local sim = require "pitwall.sim"
local track = require "pitwall.track"
local drivers = require "pitwall.drivers"

local map = track.fromSim()
local LAP = map:lapLength(0)
-- the follower at the start of piece 7 (a straight), the car it followed 120 mm behind it in the
-- same lane, on the straight before
local car = sim.addCar { lane = 2, piece = 7 }
local behind = sim.addCar { lane = 2, piece = 6, distance = sim.track().pieces[6].length - 120 }
local ctx = drivers.context(car, map, { car, behind })
-- both drive a little, so that the trackers know where they are
car:setSpeed(300, 1000)
behind:setSpeed(300, 1000)
expect.truthy(sim.runUntil(function()
  local ahead = ctx:nearby(1000)
  return ctx.loc.localized and #ahead >= 1 and ahead[1].gap < 0
end, 10), "both cars localized, the other one behind")

-- the follower, which followed `behind` until now, takes over; `behind` drives into its back
local f = drivers.load("follower").new { gap = 1.0, speed = 800 }
f.lastLead = behind
drivers.run(car, f, ctx)
behind:setSpeed(800, 1000)
local function driven(c) return sim.truth(c).laps * LAP + sim.truth(c).lapDistance end
local from = driven(car)
sim.run(10)
local moved = driven(car) - from
expect.gt(moved, 2000, "the follower drove on (" .. math.floor(moved) .. " mm in 10 s)")
expect.gt(sim.truth(behind).speed, 300, "and the car behind it is no longer held")
