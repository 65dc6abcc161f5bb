// Road piece ids (anki-overdrive.md "Track"; seed 000 §4.3.6, §4.5).
#include "engine/protocol/anki/pieces.hpp"

namespace pitwall::anki {

PieceType pieceType(std::uint8_t piece_id) {
  switch (piece_id) {
    case 34:
      return PieceType::StartLong;
    case 33:
      return PieceType::StartShort;
    case 36:
    case 39:
    case 40:
    case 48:
    case 51:
      return PieceType::Straight;
    case 17:
    case 18:
    case 20:
    case 23:
    case 24:
    case 27:
      return PieceType::Curve;
    case 10:
      return PieceType::Intersection;
    case 57:
      return PieceType::Special;
    case 58:
      return PieceType::JumpRamp;
    case 63:
      return PieceType::JumpLanding;
    default:
      return PieceType::Unknown;
  }
}

std::string_view pieceTypeName(PieceType type) {
  switch (type) {
    case PieceType::StartLong:
      return "start-long";
    case PieceType::StartShort:
      return "start-short";
    case PieceType::Straight:
      return "straight";
    case PieceType::Curve:
      return "curve";
    case PieceType::Intersection:
      return "intersection";
    case PieceType::Special:
      return "special";
    case PieceType::JumpRamp:
      return "jump-ramp";
    case PieceType::JumpLanding:
      return "jump-landing";
    case PieceType::Unknown:
      break;
  }
  return "unknown";
}

}  // namespace pitwall::anki
