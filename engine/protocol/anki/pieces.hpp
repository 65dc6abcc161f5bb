#pragma once
// Road piece ids and what they are (anki-overdrive.md "Track"; seed 000 §4.5).
#include <cstdint>
#include <string_view>

namespace pitwall::anki {

enum class PieceType {
  StartLong,     // 34: start grid, the part before the finish line
  StartShort,    // 33: the part after the finish line
  Straight,      // 36, 39, 40, 48, 51
  Curve,         // 17, 18, 20, 23, 24, 27
  Intersection,  // 10
  Special,       // 57: Fast & Furious piece
  JumpRamp,      // 58
  JumpLanding,   // 63
  Unknown,
};

PieceType pieceType(std::uint8_t piece_id);
std::string_view pieceTypeName(PieceType type);  // "start-long", "straight", "curve", …

inline constexpr double kStraightLengthMm = 560.0;
inline constexpr double kStartLongLengthMm = 340.0;
inline constexpr double kStartShortLengthMm = 220.0;
inline constexpr double kCurveRadiusMm = 280.0;  // centre line, 90° arc
inline constexpr std::uint8_t kFinishBefore = 34;  // a lap ends on the transition 34 → 33
inline constexpr std::uint8_t kFinishAfter = 33;

}  // namespace pitwall::anki
