#include "engine/laps/ghost.hpp"

#include <cmath>

namespace pitwall::laps {

sim::GhostLap ghostLap(const LapTrace& trace) {
  sim::GhostLap g;
  g.time = trace.time;
  g.length = trace.length;
  for (const TracePoint& p : trace.points) {
    g.points.push_back({p.t, p.distance});
    if (std::isfinite(p.offset)) g.lanes.push_back({p.distance, p.offset});
  }
  return g;
}

}  // namespace pitwall::laps
