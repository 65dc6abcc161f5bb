#pragma once
// Lua scripts the benchmarks share: the in-process simulator benchmark (sim_bench.cpp) and the
// command line's (cli_bench.cpp) run the same one, so their simulated seconds per CPU second
// compare.

namespace pitwall::bench {

// A realistic script: per car, a lap counter with lap times kept in onPosition handlers.
inline constexpr const char* kLapCounter = R"lua(
laps, best = {}, {}
for _, car in ipairs(pitwall.cars()) do
  local last, lapStart = nil, nil
  laps[car] = 0
  car.onPosition = function(car, ev)
    -- the finish line lies between pieces 34 and 33
    if ev.piece == 33 and last == 34 then
      if lapStart then
        local t = ev.time - lapStart
        if not best[car] or t < best[car] then best[car] = t end
      end
      lapStart = ev.time
      laps[car] = laps[car] + 1
    end
    last = ev.piece
  end
  car:setSpeed(800)
end
)lua";

}  // namespace pitwall::bench
