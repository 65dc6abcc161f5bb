// Road piece ids (anki-overdrive.md "Track").
#include "engine/protocol/anki/pieces.hpp"

#include <doctest/doctest.h>

using namespace pitwall::anki;

TEST_CASE("every listed piece id maps to its piece type") {
  CHECK(pieceType(34) == PieceType::StartLong);
  CHECK(pieceType(33) == PieceType::StartShort);
  for (int id : {36, 39, 40, 48, 51})
    CHECK(pieceType(static_cast<std::uint8_t>(id)) == PieceType::Straight);
  for (int id : {17, 18, 20, 23, 24, 27})
    CHECK(pieceType(static_cast<std::uint8_t>(id)) == PieceType::Curve);
  CHECK(pieceType(10) == PieceType::Intersection);
  CHECK(pieceType(57) == PieceType::Special);
  CHECK(pieceType(58) == PieceType::JumpRamp);
  CHECK(pieceType(63) == PieceType::JumpLanding);
}

TEST_CASE("an unlisted piece id is of unknown type") {
  CHECK(pieceType(0) == PieceType::Unknown);
  CHECK(pieceType(35) == PieceType::Unknown);
  CHECK(pieceType(255) == PieceType::Unknown);
}

TEST_CASE("piece types have kebab-case names") {
  CHECK(pieceTypeName(PieceType::StartLong) == "start-long");
  CHECK(pieceTypeName(PieceType::StartShort) == "start-short");
  CHECK(pieceTypeName(PieceType::Straight) == "straight");
  CHECK(pieceTypeName(PieceType::Curve) == "curve");
  CHECK(pieceTypeName(PieceType::Intersection) == "intersection");
  CHECK(pieceTypeName(PieceType::JumpRamp) == "jump-ramp");
  CHECK(pieceTypeName(PieceType::Unknown) == "unknown");
}

TEST_CASE("the finish line lies between the long and the short start piece") {
  CHECK(pieceType(kFinishBefore) == PieceType::StartLong);
  CHECK(pieceType(kFinishAfter) == PieceType::StartShort);
}
