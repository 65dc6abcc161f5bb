-- Saved as often as a user likes: the grand prix is saved every 0.37 s of its whole run — scan
-- lap, grid, lights, race, the end — every seventh save broken, car 1's cruiser slowed to
-- 600 mm/s from 4 s after green on. It still finishes as one race (grand_prix_saves.lua).
-- tags: race reload
local sim = require "pitwall.sim"
local gp = require "grand_prix_saves"

local saves, broken, green = 0, 0, nil
local o = gp.run {
  start = function(run)
    pitwall.every(0.37, function()
      if run.finished then return end
      saves = saves + 1
      local slow = green and pitwall.now() >= green + 4
      if saves % 7 == 0 then
        broken = broken + 1
        sim.reload((slow and gp.v2 or gp.v1) .. "\nend -- a stray end")
      else
        sim.reload(slow and (saves % 2 == 0 and gp.v2 or gp.v3) or gp.v1)
      end
    end)
  end,
  green = function(_, t)
    green = t
    return t + 4.37 -- the first save at or after green + 4
  end,
}
expect.ge(saves, 80, "saved over the whole run")
expect.eq(o.run.refused, broken, "every broken save refused")
expect.eq(o.run.version, saves - broken + 1, "every good save took over")
gp.check(o)
