-- Four AI drivers on the smallest real track we have: the okoeth oval of the real captures,
-- six pieces (2.9 m a lap), no start piece (docs/racing.md "Mapping any loop"). Side by side on
-- its one-piece grid, the lane keeper changes into the follower's lane as they pull away and
-- runs into it; held behind it, pushing, it reports nothing, and its tracker reckons it on at the
-- speed it was told — ahead of the follower, which stood for it: both stood for the rest of the
-- race (found while mapping the oval; the jam of issue 34 on another track). The follower now
-- knows the car that ran into it by that car's own collision report, and keeps it behind while it
-- reads nothing of the track (drivers/follower.lua). Every car finishes, none averaging more than
-- 1.5 times its best lap; a lapped car one lap down.
-- tags: race drivers
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local drivers = require "pitwall.drivers"

sim.setTrack("R:17 R:18 S:40 R:18 R:23 S:39")
for _ = 1, 4 do sim.addCar {} end
local lineup = {
  { "cruiser", { speed = 950 } },
  { "lanekeeper", { speed = 1000 } },
  { "follower", { speed = 1050 } },
  { "overtaker", { speed = 1100 } },
}
local LAPS = 4
local r = race.laps {
  laps = LAPS,
  scan = true,
  drivers = function(_, i) return drivers.load(lineup[i][1]).new(lineup[i][2]) end,
}
local rows = r:results()
expect.eq(#rows, 4, "four cars in the results")
for _, row in ipairs(rows) do
  local what = row.car
  expect.truthy(row.finished, what .. " finished")
  expect.ge(row.laps, LAPS - 1, what .. ": at most one lap down")
  expect.truthy(row.bestLap, what .. " has a best lap")
  if row.bestLap then
    expect.le(row.totalTime / row.laps, 1.5 * row.bestLap,
      string.format("%s: its laps average within 1.5x its best (%.2f s, best %.2f s)", what,
        row.totalTime / row.laps, row.bestLap))
  end
end
