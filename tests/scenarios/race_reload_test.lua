-- The grand prix survives saves of itself: during the scan lap, on the way to the grid, during
-- the lights, a changed driver speed mid-race, a broken version, and one more. Then it finishes
-- as one race (grand_prix_saves.lua has the checks).
-- tags: race reload
local sim = require "pitwall.sim"
local gp = require "grand_prix_saves"

local o = gp.run {
  start = function()
    sim.reload(gp.v1, 5)  -- the scan lap (it begins at once and takes over 10 s)
    sim.reload(gp.v1, 16) -- on the way to the grid
    sim.reload(gp.v1, 20) -- the lights
  end,
  green = function(_, green)
    sim.reload(gp.v2, green + 4) -- car 1's cruiser: 950 → 600 mm/s
    sim.reload("local broken = ", green + 6)
    sim.reload(gp.v3, green + 8)
    return green + 4
  end,
}
expect.eq(o.run.version, 6, "versions: the first, three before green, two mid-race")
expect.eq(o.run.refused, 1, "the broken version was refused")
expect.truthy(o.run.refusal:find("grand_prix.lua:1:", 1, true), "refused with file and line")
gp.check(o)
