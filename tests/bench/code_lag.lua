-- The live race's loop while the code page's students test (docs/performance.md "The code page's
-- tests"; run by tests/bench/code_tests_lag.py, not by ctest): every car drives its desk's driver
-- in free practice, and a timer every 5 ms measures how much later than 5 ms after its last tick
-- the loop runs it. The teacher's
-- "start" marks the phases (the bench's client presses it): before, during the tests, after.
-- Prints one line a phase — "lag PHASE n=… p50=… p99=… max=… ms" — then ends the run.
local race = require "pitwall.race"
local room = pitwall.classroom
local phases, phase = { "idle", "tests", "after" }, 1
local samples = { {}, {}, {} }
local last
pitwall.every(0.005, function()
  local now = pitwall.now()
  local s = samples[phase]
  if last then s[#s + 1] = math.max(0, now - last - 0.005) * 1000 end
  last = now
  if room.nextStart() then
    phase = phase + 1
    if phase > #phases then
      for k, name in ipairs(phases) do
        local v = samples[k]
        table.sort(v)
        local function at(q) return v[math.max(1, math.ceil(q * #v))] or 0 end
        print(string.format("lag %s n=%d p50=%.2f p99=%.2f max=%.2f ms", name, #v, at(0.5),
          at(0.99), v[#v] or 0))
      end
      io.stdout:flush()
      pitwall.stop()
    end
  end
end)
print("ready")
race.practice { minutes = 60, board = false }
