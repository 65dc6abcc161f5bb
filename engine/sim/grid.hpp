#pragma once
// Where simulated cars start when a run asks for N of them (`pitwall run --cars N`): on the
// start piece, one per lane from the left, then one piece further back for the next four.
#include <string>
#include <vector>

#include "engine/sim/world.hpp"

namespace pitwall::sim {

inline constexpr double kLaneOffsets[4] = {-68.0, -23.0, 23.0, 68.0};  // anki-overdrive.md

// Grid slot `index` (0-based) on `track`, with a model and a name of its own.
CarSpec gridSpec(const Track& track, int index);
// The model ids used for grid cars, in order (Groundshock, Skull, Thermo, Nuke, …).
std::uint8_t gridModel(int index);

}  // namespace pitwall::sim
