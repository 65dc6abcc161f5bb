-- The standings as the board and the view show them, on every update of a grand prix under the
-- real sensor model: the gap to the leader never decreases down the table, and "+N laps" only
-- for a car whole laps behind (docs/racing.md "Results").
-- tags: race
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local drivers = require "pitwall.drivers"
local track = require "pitwall.track"

local lineup = { { "cruiser", { speed = 950 } }, { "lanekeeper", { speed = 1000 } },
  { "follower", { speed = 1050 } }, { "overtaker", { speed = 1100 } } }
for _ = 1, 4 do sim.addCar {} end
local map = track.fromSim()

local checked, session = 0, nil
pitwall.spawn(function()
  pitwall.waitUntil(function() return session and session.phase == "racing" end, 120, 0.05)
  while session.phase == "racing" do
    local rows = session:results()
    for k = 2, #rows do
      local a, b = rows[k - 1], rows[k]
      local ahead = (a.lapsBehind or 0) + 0
      expect.ge(b.lapsBehind or 0, ahead, "laps behind down the table")
      if (b.lapsBehind or 0) == ahead and a.gap and b.gap then
        expect.ge(b.gap, a.gap, string.format("gap of P%d (%s %.3f) after P%d's (%s %.3f)", k,
          b.car, b.gap, k - 1, a.car, a.gap))
      end
      if b.lapsBehind and b.lapsBehind > 0 then
        local eb, el = session:entry(pitwall.car(b.car)), session:entry(pitwall.car(rows[1].car))
        expect.ge(el.progress - eb.progress, b.lapsBehind, b.car .. " is that many laps behind")
      end
    end
    checked = checked + 1
    pitwall.sleep(0.1)
  end
end)

race.laps {
  laps = 8, map = map, board = false, results = false,
  drivers = function(_, i) return drivers.load(lineup[i][1]).new(lineup[i][2]) end,
  onLights = function(_, s) session = s end,
}
expect.ge(checked, 100, "updates checked")
