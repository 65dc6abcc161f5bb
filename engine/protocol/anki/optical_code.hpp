#pragma once
// The optical code under a road piece's foil (seed 000 §4.5.1; docs/tracks.md "The code"): along
// every lane line, sections of strokes run parallel to the line on both sides. A section is a
// boundary stroke, 7 bit strokes and a boundary stroke. The piece side carries the piece id, the
// location side the location id; a thick stroke is 1, a thin one 0, most significant bit first
// in the piece's forward direction. A boundary is thin on the piece side and wide on the location
// side: that asymmetry tells a reader which side is which, so it reads the same ids from either
// direction (reversed, it reads the bits in reverse order, as the seed says the cars do).
// Pure: marks in, ids out. The widths and the geometry are in engine/sim/code_layout.hpp.
#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "engine/core/result.hpp"

namespace pitwall::anki::optical {

inline constexpr int kBits = 7;                  // bits per id (§4.5.1: "always 7 strokes")
inline constexpr int kMaxId = (1 << kBits) - 1;  // 127
inline constexpr int kStrokes = kBits + 2;       // a section: boundary, 7 bits, boundary

// A stroke's width class, on one side of the lane line.
enum class Width : std::uint8_t { None, Thin, Thick, Wide };
const char* widthName(Width w);

// One stroke as seen across the line: its width left and right of it (in the reader's frame).
struct Stroke {
  Width left = Width::None;
  Width right = Width::None;
  bool operator==(const Stroke&) const = default;
};

// The 9 strokes of a section in the piece's forward direction (left = the piece side).
std::array<Stroke, kStrokes> encodeSection(int piece_id, int location_id);

struct Reading {
  int piece_id = 0;
  int location_id = 0;
  bool reversed = false;  // the reader drove against the piece's forward direction
};

// The ids of one section from its strokes in the order a reader met them, left and right in its
// own frame; an error sentence when they do not form a section (count, boundary, a stroke
// missing or of the wrong width on one side).
Result<Reading, std::string> decodeSection(std::span<const Stroke> strokes);

}  // namespace pitwall::anki::optical
