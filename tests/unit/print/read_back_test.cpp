// Printed pieces read back by the sensor model: every piece type, every row, both directions,
// decodes to the ids the design gives it; a missing stroke or a scaled page does not.
#include <doctest/doctest.h>

#include <algorithm>
#include <string>

#include "engine/print/raster.hpp"
#include "engine/print/sensor.hpp"
#include "engine/sim/code_layout.hpp"
#include "engine/sim/track.hpp"

using namespace pitwall;

namespace {

// 8 px/mm (203 dpi): coarser than a printer, fine enough for the thinnest stroke (0.52 mm).
constexpr double kPxPerMm = 8;

std::vector<sim::Piece> piecesOf(const std::string& token) {
  auto pieces = sim::parsePiece(token);
  REQUIRE_MESSAGE(pieces.ok(), token);
  return *pieces;
}

sim::Piece onePiece(const std::string& token) {
  auto pieces = piecesOf(token);
  REQUIRE(pieces.size() == 1);
  return pieces.front();
}

bool mentions(const print::RowPass& pass, const std::string& text) {
  for (const auto& p : pass.problems)
    if (p.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST_CASE("print: every piece type reads back on every row in both directions as designed") {
  for (const std::string token :
       {"S:36", "L:17", "R:17", "start", "S:60,len=300", "L:61,r=400,deg=45"}) {
    for (const sim::Piece& piece : piecesOf(token)) {
      CAPTURE(token);
      CAPTURE(static_cast<int>(piece.id));
      const print::Raster raster = print::renderPiece(piece, kPxPerMm);
      const print::ReadBack result = print::readBack(raster, piece);
      const sim::CodeLayout layout = sim::codeLayout(piece);
      // Judged here from the design, not from the sensor's own verdict.
      REQUIRE(result.passes.size() == 2 * layout.rows.size());
      int readings = 0;
      for (const print::RowPass& pass : result.passes) {
        CAPTURE(pass.row);
        CAPTURE(pass.reversed);
        CHECK(pass.problems.empty());
        const sim::CodeRow& row = layout.rows[static_cast<std::size_t>(pass.row)];
        REQUIRE(row.sections > 0);
        REQUIRE(static_cast<int>(pass.readings.size()) == row.sections);
        for (int k = 0; k < row.sections; ++k) {
          const auto& r = pass.readings[static_cast<std::size_t>(k)];
          CHECK(r.piece_id == piece.id);
          CHECK(r.location_id == row.locationOf(pass.reversed ? row.sections - 1 - k : k));
          CHECK(r.reversed == pass.reversed);
          ++readings;
        }
      }
      CHECK(readings == 2 * layout.locations);
      CHECK(result.ok());
    }
  }
}

TEST_CASE("print: a stroke left white fails the read-back, naming its row and section") {
  for (const std::string token : {"S:60,len=300", "L:61,r=400,deg=45"}) {
    CAPTURE(token);
    const sim::Piece piece = onePiece(token);
    print::DrawOptions options;
    // A bit stroke on the location side of row 4's last section (the curve's inner rows have one).
    const sim::CodeRow row = sim::codeLayout(piece).rows[3];
    const int section = row.sections - 1;
    options.omit = print::StrokeRef{3, section, 4, false};
    const print::ReadBack result =
        print::readBack(print::renderPiece(piece, kPxPerMm, {}, options), piece);
    CHECK_FALSE(result.ok());
    const int location = row.locationOf(section);
    for (const print::RowPass& pass : result.passes) {
      CAPTURE(pass.row);
      CAPTURE(pass.reversed);
      if (pass.row != 3) {
        CHECK(pass.problems.empty());
        continue;
      }
      // Both directions see it, and say where.
      REQUIRE(pass.problems.size() == 1);
      CHECK(mentions(pass, "section " + std::to_string(section + 1) + " (piece " +
                               std::to_string(piece.id) + ", location " + std::to_string(location) +
                               ")"));
      CHECK(mentions(pass, "location side"));
    }
    const std::string text = print::report(result, piece, "p.svg");
    const std::string named = "section " + std::to_string(section + 1);
    CHECK(text.find("p.svg: row 4 forward:  " + named) != std::string::npos);
    CHECK(text.find("p.svg: row 4 backward: " + named) != std::string::npos);
    CHECK(text.find("FAILED") != std::string::npos);
  }
}

TEST_CASE("print: a boundary stroke left white fails the read-back too") {
  const sim::Piece piece = onePiece("S:36");
  print::DrawOptions options;
  options.omit = print::StrokeRef{15, 0, 0, false};  // the wide side of the first boundary
  const print::ReadBack result =
      print::readBack(print::renderPiece(piece, kPxPerMm, {}, options), piece);
  CHECK_FALSE(result.ok());
  for (const print::RowPass& pass : result.passes) {
    CAPTURE(pass.row);
    CHECK(pass.problems.empty() == (pass.row != 15));
    if (pass.row == 15) CHECK(mentions(pass, "section 1"));
  }
}

TEST_CASE("print: a page printed 3 % too large or too small fails with the scale named") {
  for (const std::string token : {"S:60,len=300", "L:17", "L:61,r=400,deg=45"}) {
    const sim::Piece piece = onePiece(token);
    for (double scale : {1.03, 0.97}) {
      CAPTURE(token);
      CAPTURE(scale);
      const print::ReadBack result =
          print::readBack(print::renderPiece(piece, kPxPerMm, {}, {}, scale), piece);
      CHECK_FALSE(result.ok());
      const std::string said =
          scale > 1 ? "% further apart than designed: the page was scaled; print at actual size"
                    : "% closer together than designed: the page was scaled; print at actual size";
      // Every row in both directions sees it (the ids themselves may still read), and measures
      // it.
      for (const print::RowPass& pass : result.passes) {
        CAPTURE(pass.row);
        CAPTURE(pass.reversed);
        CHECK(mentions(pass, said));
        CHECK(pass.spacing_ratio == doctest::Approx(scale).epsilon(0.003));
      }
      CHECK(print::report(result, piece, "p.svg")
                .find(scale > 1 ? "strokes 3.0 % further apart" : "strokes 3.0 % closer") !=
            std::string::npos);
    }
  }
}

TEST_CASE("print: a page within the scale tolerance still reads as designed") {
  const sim::Piece piece = onePiece("S:36");
  const print::ReadBack result =
      print::readBack(print::renderPiece(piece, kPxPerMm, {}, {}, 1.004), piece);
  CHECK(result.ok());
  for (const print::RowPass& pass : result.passes)
    CHECK(pass.spacing_ratio == doctest::Approx(1.004).epsilon(0.002));
}

TEST_CASE("print: a blank page reads nothing and says the line was lost") {
  const sim::Piece piece = onePiece("S:36");
  print::Raster raster = print::renderPiece(piece, 2);
  std::fill(raster.dark.begin(), raster.dark.end(), 0);
  const print::ReadBack result = print::readBack(raster, piece);
  CHECK_FALSE(result.ok());
  for (const print::RowPass& pass : result.passes) {
    CHECK(mentions(pass, "lost the line"));
    CHECK(mentions(pass, "found 0 sections where the design has"));
  }
}

TEST_CASE("print: the report of a good piece is its verdict; every row only when verbose") {
  const sim::Piece piece = onePiece("S:36");
  const print::ReadBack result = print::readBack(print::renderPiece(piece, kPxPerMm), piece);
  REQUIRE(result.ok());
  const std::string brief = print::report(result, piece, "p.svg");
  CHECK(brief ==
        "p.svg: OK: S:36 (piece 36), 96 section readings on 16 rows in both directions all "
        "decode to the design\n");
  const std::string verbose = print::report(result, piece, "p.svg", true);
  CHECK(std::count(verbose.begin(), verbose.end(), '\n') == 33);
  CHECK(verbose.find("p.svg: row 16 backward: OK, 3 sections\n") != std::string::npos);
  CHECK(verbose.ends_with(brief));
}

TEST_CASE("print: the report of a bad piece names the rows that fail, and no good one") {
  const sim::Piece piece = onePiece("S:36");
  print::DrawOptions options;
  options.omit = print::StrokeRef{15, 0, 0, false};  // row 16's first boundary, wide side
  const print::ReadBack result =
      print::readBack(print::renderPiece(piece, kPxPerMm, {}, options), piece);
  REQUIRE_FALSE(result.ok());
  const std::string text = print::report(result, piece, "p.svg");
  CHECK(text.find("p.svg: row 16 forward:  section 1") != std::string::npos);
  CHECK(text.find("OK, ") == std::string::npos);
  CHECK(text.find("p.svg: FAILED: S:36 (piece 36), 2 of 32 row readings") != std::string::npos);
}
