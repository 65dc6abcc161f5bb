#pragma once
// A lap's trace as the simulator's ghost drives it (sim.addGhost; docs/simulator.md "Ghosts"):
// its distance against time, and the lane it reported (on the road: clamped to ±70 mm).
#include "engine/laps/trace.hpp"
#include "engine/sim/world.hpp"

namespace pitwall::laps {

sim::GhostLap ghostLap(const LapTrace& trace);

}  // namespace pitwall::laps
