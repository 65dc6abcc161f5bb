#pragma once
// A lap's trace as the simulator's ghost drives it (sim.addGhost, `pitwall run --ghost`;
// docs/simulator.md "Ghosts"): its distance against time, and the lane it reported.
#include "engine/laps/trace.hpp"
#include "engine/sim/world.hpp"

namespace pitwall::laps {

sim::GhostLap ghostLap(const LapTrace& trace);

}  // namespace pitwall::laps
