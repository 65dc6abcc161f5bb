// Printing pieces: paper and tiles, what a PIECE|FILE names, the SVG's metadata and its reading
// back through librsvg.
#include "engine/print/print.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/print/raster.hpp"
#include "engine/print/sensor.hpp"
#include "engine/print/svg_metadata.hpp"
#include "tests/support/temp_dir.hpp"

using namespace pitwall;

namespace {

struct TempDir : pitwall::testing::TempDir {
  TempDir() : pitwall::testing::TempDir("pitwall-print") {}
};

void write(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

}  // namespace

TEST_CASE("print: papers are A4 and A3, portrait or landscape; another name is refused") {
  auto a4 = print::paperNamed("a4", false);
  REQUIRE(a4.ok());
  CHECK(a4->width_mm == 210);
  CHECK(a4->height_mm == 297);
  auto a3 = print::paperNamed("A3", true);
  REQUIRE(a3.ok());
  CHECK(a3->width_mm == 420);
  CHECK(a3->height_mm == 297);
  auto letter = print::paperNamed("letter", false);
  REQUIRE_FALSE(letter.ok());
  CHECK(letter.error() == "unknown paper 'letter': use a4 or a3");
}

TEST_CASE("print: tiles cover the sheet with the overlap repeated and no tile to spare") {
  const print::Paper a4 = *print::paperNamed("a4", false);
  // Printable 200 × 273 mm (a 14 mm band for the label and ruler), tiles 195 × 268 mm apart.
  const auto one = print::tiling(200, 273, a4);
  CHECK(one.pages() == 1);
  const auto two = print::tiling(201, 273, a4);
  CHECK(two.columns == 2);
  CHECK(two.rows == 1);
  CHECK(two.step_x_mm == doctest::Approx(195));
  const auto wide = print::tiling(200 + 195, 274, a4);
  CHECK(wide.columns == 2);
  CHECK(wide.rows == 2);
  CHECK(print::tiling(200 + 195 + 1, 10, a4).columns == 3);
}

TEST_CASE("print: a piece token, start, a layout name or a layout file name their pieces") {
  auto start = print::piecesOf("start");
  REQUIRE(start.ok());
  REQUIRE(start->size() == 2);
  CHECK((*start)[0].id == 34);
  CHECK((*start)[1].id == 33);
  auto custom = print::piecesOf("L:61,r=400,deg=45");
  REQUIRE(custom.ok());
  REQUIRE(custom->size() == 1);
  CHECK(custom->front().radius() == 400);
  auto oval = print::piecesOf("oval");
  REQUIRE(oval.ok());
  CHECK(oval->size() > 4);

  TempDir dir;
  write(dir.file("t.txt"), "start S:36 L:17 L:17 S:36 S:36 L:17 L:17\n");
  auto file = print::piecesOf(dir.file("t.txt"));
  REQUIRE_MESSAGE(file.ok(), (file.ok() ? "" : file.error()));
  CHECK(file->size() == 9);

  // a stock piece by its id alone: 40 is S:40, 17 L:17, 34 the start's first piece alone
  auto straight = print::piecesOf("40");
  REQUIRE(straight.ok());
  REQUIRE(straight->size() == 1);
  CHECK(straight->front().id == 40);
  CHECK(straight->front().type == anki::PieceType::Straight);
  auto curve = print::piecesOf("17");
  REQUIRE(curve.ok());
  CHECK(curve->front().turn == 1);
  auto first = print::piecesOf("34");
  REQUIRE(first.ok());
  REQUIRE(first->size() == 1);
  CHECK(first->front().type == anki::PieceType::StartLong);
  CHECK(print::piecesOf("10").error().find("intersection") != std::string::npos);
  CHECK(print::piecesOf("60").error().find("not one of Anki's stock pieces") != std::string::npos);

  auto bad = print::piecesOf("Q:9");
  REQUIRE_FALSE(bad.ok());
  CHECK(bad.error().find("Q:9") != std::string::npos);
  CHECK(bad.error().find("no file is named 'Q:9'") != std::string::npos);
}

TEST_CASE("print: the metadata goes in after the svg tag and reads back; garbage is refused") {
  print::PieceSvg p{"S:60,len=300", 60, {324, 208, 20, 104}, {}};
  const std::string svg = print::withMetadata(
      "<?xml version=\"1.0\"?>\n<svg width=\"324mm\" height=\"208mm\"><g/></svg>", p);
  CHECK(svg.find("<svg width=\"324mm\" height=\"208mm\">\n<metadata") != std::string::npos);
  auto back = print::readMetadata(svg);
  REQUIRE(back.ok());
  CHECK(back->token == "S:60,len=300");
  CHECK(back->piece_id == 60);
  CHECK(back->sheet.width_mm == 324);
  CHECK(back->sheet.origin_y_mm == 104);

  CHECK_FALSE(print::readMetadata("<svg/>").ok());
  CHECK_FALSE(print::readMetadata("<pitwall:piece token=\"S\"").ok());
  CHECK_FALSE(print::readMetadata("<pitwall:piece token=\"S\" piece-id=\"36\"/>").ok());
  std::string nan = svg;
  nan.replace(nan.find("324.0000"), 8, "nan");
  CHECK_FALSE(print::readMetadata(nan).ok());
}

TEST_CASE("print: an SVG is 1:1 in mm, and librsvg's rendering of it reads back as designed") {
  const sim::Piece piece = print::piecesOf("S:60,len=300")->front();
  auto svg = print::pieceSvg(piece);
  REQUIRE(svg.ok());
  const print::Sheet sheet = print::sheetFor(piece);
  std::ostringstream size;
  size << "width=\"" << sheet.width_mm << "mm\" height=\"" << sheet.height_mm
       << "mm\" viewBox=\"0 0 " << sheet.width_mm << " " << sheet.height_mm << "\"";
  CHECK(svg->find(size.str()) != std::string::npos);

  TempDir dir;
  write(dir.file("p.svg"), *svg);
  auto loaded = print::loadPieceSvg(dir.file("p.svg"), 200);
  REQUIRE_MESSAGE(loaded.ok(), (loaded.ok() ? "" : loaded.error()));
  CHECK(loaded->first.width == static_cast<int>(std::ceil(sheet.width_mm / 25.4 * 200)));
  CHECK(print::readBack(loaded->first, piece).ok());

  // Its width and height made 3 % larger: a printer prints it larger, and the reader says so.
  std::string scaled = *svg;
  std::ostringstream big;
  big << "width=\"" << sheet.width_mm * 1.03 << "mm\" height=\"" << sheet.height_mm * 1.03
      << "mm\"";
  scaled.replace(scaled.find("width="), size.str().find(" viewBox"), big.str());
  write(dir.file("big.svg"), scaled);
  auto bigger = print::loadPieceSvg(dir.file("big.svg"), 200);
  REQUIRE(bigger.ok());
  const auto result = print::readBack(bigger->first, piece);
  CHECK_FALSE(result.ok());
  CHECK(print::report(result, piece, "big.svg").find("further apart than designed") !=
        std::string::npos);
}

TEST_CASE("print: files that are no piece SVG are refused with a sentence naming them") {
  TempDir dir;
  auto missing = print::loadPieceSvg(dir.file("none.svg"), 300);
  REQUIRE_FALSE(missing.ok());
  CHECK(missing.error().find("cannot read " + dir.file("none.svg")) == 0);

  write(dir.file("plain.svg"), "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10mm\"/>");
  auto plain = print::loadPieceSvg(dir.file("plain.svg"), 300);
  REQUIRE_FALSE(plain.ok());
  CHECK(plain.error().find("is not a piece SVG written by `pitwall track print`") !=
        std::string::npos);

  write(dir.file("broken.svg"),
        "<svg <pitwall:piece token=\"S\" piece-id=\"36\" width-mm=\"1\" height-mm=\"1\" "
        "start-x-mm=\"0\" start-y-mm=\"0\"/>");
  auto broken = print::loadPieceSvg(dir.file("broken.svg"), 300);
  REQUIRE_FALSE(broken.ok());
  CHECK(broken.error().find("is not an SVG librsvg can read") != std::string::npos);

  write(dir.file("huge.svg"),
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"100000mm\" height=\"100000mm\">"
        "<metadata><pitwall:piece xmlns:pitwall=\"urn:pitwall:piece:1\" token=\"S\" "
        "piece-id=\"36\" width-mm=\"1\" height-mm=\"1\" start-x-mm=\"0\" start-y-mm=\"0\"/>"
        "</metadata></svg>");
  auto huge = print::loadPieceSvg(dir.file("huge.svg"), 300);
  REQUIRE_FALSE(huge.ok());
  CHECK(huge.error().find("use a lower --dpi") != std::string::npos);
}

TEST_CASE("print: a PDF has a page per tile of every piece") {
  TempDir dir;
  const auto paper = *print::paperNamed("a4", false);
  const auto pieces = *print::piecesOf("start");
  auto pages = print::writePdf(dir.file("s.pdf"), pieces, paper);
  REQUIRE(pages.ok());
  int expected = 0;
  for (const auto& p : pieces) {
    const auto sheet = print::sheetFor(p);
    expected += print::tiling(sheet.width_mm, sheet.height_mm, paper).pages();
  }
  CHECK(*pages == expected);
  CHECK(std::filesystem::file_size(dir.file("s.pdf")) > 1000);

  auto unwritable = print::writePdf(dir.file("no/such/dir.pdf"), pieces, paper);
  REQUIRE_FALSE(unwritable.ok());
  CHECK(unwritable.error().find("cannot write") == 0);
}

TEST_CASE("print: a tile's window leaves out only strokes that lie outside it") {
  for (const std::string token : {"S:36", "L:17", "L:61,r=400,deg=45"}) {
    CAPTURE(token);
    const sim::Piece piece = print::piecesOf(token)->front();
    const print::Sheet sheet = print::sheetFor(piece);
    const print::Raster whole = print::renderPiece(piece, 4);
    print::DrawOptions options;
    const double cut = sheet.width_mm / 2;
    options.window = print::Window{0, 0, cut, sheet.height_mm};
    const print::Raster half = print::renderPiece(piece, 4, {}, options);
    REQUIRE(half.width == whole.width);
    long inside_differ = 0, outside_whole = 0, outside_half = 0;
    for (int y = 0; y < whole.height; ++y)
      for (int x = 0; x < whole.width; ++x) {
        const auto i = static_cast<std::size_t>(y) * whole.width + x;
        if (x < cut * 4)
          inside_differ += whole.dark[i] != half.dark[i];
        else if (x > (cut + 10) * 4)
          outside_whole += whole.dark[i] > 128, outside_half += half.dark[i] > 128;
      }
    CHECK(inside_differ == 0);
    // The strokes far outside were left out (the lane lines, about as dark as they, stay).
    CHECK(outside_half < outside_whole * 3 / 4);
  }
}
