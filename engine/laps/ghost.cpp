#include "engine/laps/ghost.hpp"

#include <algorithm>
#include <cmath>

#include "engine/protocol/anki/limits.hpp"

namespace pitwall::laps {

sim::GhostLap ghostLap(const LapTrace& trace) {
  sim::GhostLap g;
  g.time = trace.time;
  g.length = trace.length;
  for (const TracePoint& p : trace.points) {
    g.points.push_back({p.t, p.distance});
    // a lane on the road: a record's offsets are any numbers
    if (std::isfinite(p.offset))
      g.lanes.push_back({p.distance, std::clamp<double>(p.offset, anki::limits::kOffsetMin,
                                                        anki::limits::kOffsetMax)});
  }
  return g;
}

}  // namespace pitwall::laps
