-- A save that briefly empties the script (an editor that truncates the file, then writes it):
-- the empty version runs for 0.3 s without the race, then the next save takes the race up
-- again — it was carried on through the version that never loaded pitwall.race, and finishes
-- as one race (grand_prix_saves.lua; no car crosses the line in those 0.3 s, so no lap goes
-- untimed).
-- tags: race reload
local sim = require "pitwall.sim"
local gp = require "grand_prix_saves"

local o = gp.run {
  green = function(_, green)
    sim.reload(gp.v2, green + 4)
    sim.reload("-- (an empty buffer)", green + 5)
    sim.reload(gp.v2, green + 5.3)
    return green + 4
  end,
}
expect.eq(o.run.version, 4, "every save took over, the empty one too")
gp.check(o)
