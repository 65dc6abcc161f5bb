#pragma once
// Where a layout's pieces lie on the floor, and whether two of them overlap (docs/tracks.md
// "Rules"): each piece's road (±96 mm) as a polygon, compared with every piece that does not
// touch it end to end. Boost.Geometry does the polygon work.
#include <optional>
#include <utility>
#include <vector>

#include "engine/sim/track.hpp"

namespace pitwall::sim {

inline constexpr double kRoadHalfWidthMm = 96;  // simulator.md: the road is ±96 mm

// The first two pieces (indices into `pieces`, walked from (0, 0) heading +x) whose roads
// overlap by more than a sliver, or nothing.
std::optional<std::pair<std::size_t, std::size_t>> firstOverlap(const std::vector<Piece>& pieces);

}  // namespace pitwall::sim
