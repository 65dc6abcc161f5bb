#pragma once
// Where simulated cars start when a run asks for N of them (`pitwall run --cars N`): on the
// start piece, one per lane from the left, then one piece further back for the next four.
#include <string>
#include <vector>

#include "engine/sim/world.hpp"

namespace pitwall::sim {

inline constexpr double kLaneOffsets[4] = {-68.0, -23.0, 23.0, 68.0};  // anki-overdrive.md

// Grid slot `index` (0-based) on `track`, with a model and a name of its own. Slots from
// gridCapacity(track) on would stand on cars already there (the grid wraps round the track).
CarSpec gridSpec(const Track& track, int index);
// How many cars the grid of `track` holds: a row of four on each piece.
int gridCapacity(const Track& track);
// The layout of an oval whose grid holds `cars` (at least the default oval): the default oval's
// straights made longer, `start S×a L L S×(a+1) L L`.
std::string ovalLayoutFor(int cars);
// The model ids used for grid cars, in order (Groundshock, Skull, Thermo, Nuke, …).
std::uint8_t gridModel(int index);

}  // namespace pitwall::sim
