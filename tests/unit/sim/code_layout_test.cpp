#include "engine/sim/code_layout.hpp"

#include <doctest/doctest.h>

#include <set>

using namespace pitwall;
using namespace pitwall::sim;

namespace {

Piece stock(std::uint8_t id, int turn = 0) {
  return Piece{id, anki::pieceType(id), turn};
}

}  // namespace

TEST_CASE("code layout: the stock pieces carry the location ids real pieces report") {
  // anki-overdrive.md "Track": straight 0–47, curve 0–37, piece 33 0–15, piece 34 0–31.
  CHECK(codeLayout(stock(36)).locations == 48);
  CHECK(codeLayout(stock(17, 1)).locations == 38);
  CHECK(codeLayout(stock(17, -1)).locations == 38);
  CHECK(codeLayout(stock(33)).locations == 16);
  CHECK(codeLayout(stock(34)).locations == 32);
  // a left curve's left rows are inner: fewer sections there
  auto left = codeLayout(stock(17, 1));
  CHECK(left.rows.front().sections == 1);
  CHECK(left.rows.back().sections == 3);
  auto right = codeLayout(stock(17, -1));
  CHECK(right.rows.front().sections == 3);
  CHECK(right.rows.back().sections == 1);
}

TEST_CASE("code layout: every location id lies in exactly one row and section, in order") {
  for (const Piece& p : {stock(36), stock(17, 1), stock(18, -1), stock(33), stock(34),
                         Piece{60, anki::PieceType::Straight, 0, 300},
                         Piece{61, anki::PieceType::Curve, 1, 0, 400, 45}}) {
    CAPTURE(int(p.id));
    auto layout = codeLayout(p);
    REQUIRE(layout.rows.size() == 16);
    std::set<int> seen;
    for (int r = 0; r < 16; ++r) {
      const CodeRow& row = layout.rows[static_cast<std::size_t>(r)];
      CHECK(row.sections >= 1);
      CHECK(row.length_mm / row.sections >= 150 - 1e-9);
      for (int k = 0; k < row.sections; ++k) {
        int id = row.locationOf(k);
        CHECK(seen.insert(id).second);
        auto spot = locateCode(p, id);
        REQUIRE(spot);
        CHECK(spot->row == r);
        CHECK(spot->section == k);
        auto strokes = strokeCentres(row, k);
        // the section's strokes lie inside the row, in order, one pitch apart
        CHECK(strokes.front() > 0);
        CHECK(strokes.back() < row.length_mm);
        CHECK(strokes[1] - strokes[0] == doctest::Approx(16.5));
      }
    }
    CHECK(static_cast<int>(seen.size()) == layout.locations);
    CHECK_FALSE(locateCode(p, layout.locations));
    CHECK_FALSE(locateCode(p, -1));
  }
}

TEST_CASE("code layout: a right curve is its left curve's piece driven backwards") {
  // Anki's curves are one piece: laid the other way round it turns right, and a car reads its
  // code backwards. The ids of a right curve are the left curve's, row for row mirrored and
  // section for section reversed, at the same places.
  for (const Piece& left : {stock(17, 1), Piece{61, anki::PieceType::Curve, 1, 0, 400, 45}}) {
    Piece right = left;
    right.turn = -1;
    auto l = codeLayout(left);
    auto r = codeLayout(right);
    CHECK(r.locations == l.locations);
    for (std::size_t i = 0; i < 16; ++i) {
      const CodeRow& rr = r.rows[i];
      const CodeRow& lr = l.rows[15 - i];
      CHECK(rr.offset_mm == -lr.offset_mm);
      CHECK(rr.length_mm == doctest::Approx(lr.length_mm));
      REQUIRE(rr.sections == lr.sections);
      for (int k = 0; k < rr.sections; ++k) {
        CHECK(rr.locationOf(k) == lr.locationOf(lr.sections - 1 - k));
        auto rs = locateCode(right, rr.locationOf(k));
        auto ls = locateCode(left, rr.locationOf(k));
        REQUIRE(rs);
        REQUIRE(ls);
        CHECK(rs->fraction == doctest::Approx(1 - ls->fraction));
      }
    }
    CHECK(printedPiece(right).turn == 1);
  }
}

TEST_CASE("code layout: codeFractions is locateCode's fraction for every id, and no more") {
  for (const Piece& p : {stock(36, 0), stock(17, 1), stock(17, -1), stock(34, 0), stock(33, 0),
                         Piece{60, anki::PieceType::Straight, 0, 300},
                         Piece{61, anki::PieceType::Curve, -1, 0, 400, 45}}) {
    CAPTURE(p.id);
    CAPTURE(p.turn);
    const auto fractions = codeFractions(p);
    REQUIRE(fractions.size() == static_cast<std::size_t>(codeLayout(p).locations));
    for (std::size_t k = 0; k < fractions.size(); ++k)
      CHECK(fractions[k] == locateCode(p, static_cast<int>(k))->fraction);
    CHECK_FALSE(locateCode(p, static_cast<int>(fractions.size())));
  }
}
