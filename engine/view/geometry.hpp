#pragma once
// The track as drawn (docs/view.md): where every piece lies, in millimetres, and where a car at a
// piece, a fraction of it and an offset is. The race view, `pitwall track show` and replays
// share it. Frame: x to the right, y up (mathematical), the start piece (34) begins at (0, 0)
// heading along +x; headings in degrees counter-clockwise from +x.
#include <nlohmann/json.hpp>
#include <string>

#include "engine/sim/footprint.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::view {

inline constexpr double kRoadHalfWidthMm = sim::kRoadHalfWidthMm;  // simulator.md: ±96 mm
inline constexpr double kLaneOffsetsMm[4] = {-68, -23, 23, 68};    // the four lanes

using Pose = sim::Pose;  // mm; heading in degrees, counter-clockwise from +x

// Where piece `index` begins (its centre line), walking from the start piece.
Pose pieceStart(const sim::Track& track, std::size_t index);
// The point `fraction` (0…1) along piece `index`, `offset_mm` right of the centre line (+ right
// in driving direction), and the heading there.
Pose pointOnTrack(const sim::Track& track, std::size_t index, double fraction, double offset_mm);

// The track for the view's feed: name, source, lanes, pieces with their start poses, finish
// line and bounds (docs/view.md "track").
nlohmann::json trackJson(const sim::Track& track, const std::string& source);
// A standalone SVG drawing of the track: road, lanes, finish line, piece numbers.
std::string trackSvg(const sim::Track& track);
// A few lines of text: pieces, lap length per lane, size of the table it needs.
std::string trackSummary(const sim::Track& track);

}  // namespace pitwall::view
