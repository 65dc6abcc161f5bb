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
        int id = row.first_location + k;
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
