// --code NAME=VALUE (docs/cli.md "track print"): the stroke dimensions a user calibrates, each
// refused with a sentence naming it when it is no number of mm or the sensor could not read it,
// written into a piece SVG's metadata and read back with it.
#include "engine/print/code_options.hpp"

#include <doctest/doctest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "engine/print/print.hpp"
#include "engine/print/raster.hpp"
#include "engine/print/sensor.hpp"
#include "engine/print/svg_metadata.hpp"

using namespace pitwall;

namespace {

Result<sim::CodeGeometry, std::string> code(std::vector<std::string> items) {
  return print::withOverrides({}, items);
}

// The error of `items`, which must be refused.
std::string refusal(std::vector<std::string> items) {
  auto g = code(items);
  REQUIRE_FALSE(g.ok());
  return g.error();
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

sim::Piece onePiece(const std::string& token) {
  auto pieces = sim::parsePiece(token);
  REQUIRE(pieces.ok());
  REQUIRE(pieces->size() == 1);
  return pieces->front();
}

}  // namespace

TEST_CASE("print: --code changes the stroke dimensions it names and keeps the others") {
  auto g = code({"thick=1.4", "stroke_pitch=16", "gap=0.9"});
  REQUIRE(g.ok());
  const sim::CodeGeometry defaults;
  CHECK(g->thick_mm == 1.4);
  CHECK(g->stroke_pitch_mm == 16);
  CHECK(g->gap_mm == 0.9);
  CHECK(g->thin_mm == defaults.thin_mm);
  CHECK(g->wide_mm == defaults.wide_mm);
  CHECK(g->rows == defaults.rows);
  CHECK(g->row_pitch_mm == defaults.row_pitch_mm);
  CHECK(g->section_min_mm == defaults.section_min_mm);
  CHECK(print::codeDifferences(*g) == "stroke_pitch 16.00 mm, gap 0.90 mm, thick 1.40 mm");
  CHECK(print::codeDifferences(defaults).empty());
  CHECK(code({}).ok());
}

TEST_CASE("print: --code given the same name twice takes the last value") {
  auto g = code({"thick=1.4", "thick=1.5"});
  REQUIRE(g.ok());
  CHECK(g->thick_mm == 1.5);
  // and only the whole is checked: on the way, thick may pass wide
  auto h = code({"thick=2.5", "wide=2.55", "thick=1.3", "wide=2"});
  REQUIRE(h.ok());
  CHECK(h->wide_mm == 2);
}

TEST_CASE("print: every --code dimension is named in the list, with its default") {
  std::vector<std::string> names;
  for (const auto& d : print::codeDimensions()) names.emplace_back(d.name);
  CHECK(names == std::vector<std::string>{"stroke_pitch", "stroke_length", "line_width", "gap",
                                          "thin", "thick", "wide"});
  CHECK_FALSE(print::codeProblem(sim::CodeGeometry{}).has_value());
}

TEST_CASE("print: --code refuses an unknown name, listing the known ones and the nearest") {
  const std::string e = refusal({"thikc=1.4"});
  CHECK(has(e, "--code thikc=1.4: unknown code dimension 'thikc' (did you mean thick?)"));
  CHECK(has(e, "stroke_pitch, stroke_length, line_width, gap, thin, thick, wide"));
  CHECK(has(refusal({"thick_mm=1.4"}), "(did you mean thick?)"));
  CHECK_FALSE(has(refusal({"colour=1"}), "did you mean"));
}

TEST_CASE("print: --code refuses rows, row_pitch and section_min: they decide the location ids") {
  for (const std::string name : {"rows", "row_pitch", "section_min"}) {
    const std::string e = refusal({name + "=10"});
    CHECK(has(e, "--code " + name + "=10: " + name +
                     " decides the location ids the simulator reports, so it stays as it is"));
  }
}

TEST_CASE("print: --code refuses a value that is no number of mm, naming it") {
  CHECK(has(refusal({"thick=abc"}),
            "--code thick=abc: 'abc' is not a number; give thick in mm, e.g. --code thick=1.31"));
  CHECK(has(refusal({"thick="}), "'' is not a number"));
  CHECK(has(refusal({"thick=nan"}), "'nan' is not a number"));
  CHECK(has(refusal({"thick=NaN"}), "'NaN' is not a number"));
  CHECK(has(refusal({"thick=1.4mm"}), "'1.4mm' is not a number"));
  CHECK(has(refusal({"thick= 1.4"}), "' 1.4' is not a number"));
  CHECK(has(refusal({"thick=+1.4"}), "'+1.4' is not a number"));
  CHECK(has(refusal({"thick=1.4=2"}), "'1.4=2' is not a number"));
  CHECK(has(refusal({"thick=inf"}), "thick inf is beyond 50 mm"));
  CHECK(has(refusal({"thick=1e309"}), "thick 1e309 is beyond 50 mm"));
  CHECK(has(refusal({"thick=" + std::string(400, '9')}), "is beyond 50 mm"));
  CHECK(has(refusal({"thick=51"}), "--code thick=51: thick 51 is beyond 50 mm"));
  CHECK(has(refusal({"thick=0"}), "--code thick=0: thick must be more than 0"));
  CHECK(has(refusal({"thick=-1.4"}), "thick must be more than 0"));
  CHECK(has(refusal({"thick=-0"}), "thick must be more than 0"));
}

TEST_CASE("print: --code refuses hostile text with a sentence, never a crash") {
  CHECK(has(refusal({""}), "--code '' has no '=': give NAME=VALUE in mm"));
  CHECK(has(refusal({"thick"}), "--code thick has no '='"));
  CHECK(has(refusal({"="}), "--code = names no dimension"));
  CHECK(has(refusal({"=1.4"}), "--code =1.4 names no dimension"));
  CHECK(has(refusal({"\xff\xfe=1"}), "unknown code dimension '\\xff\\xfe'"));
  CHECK(has(refusal({std::string("thi\0ck=1", 8)}), "unknown code dimension 'thi\\x00ck'"));
  CHECK(has(refusal({"thick=\x1b[31m"}), "'\\x1b[31m' is not a number"));
  // A long name is cut short in the sentence.
  const std::string e = refusal({std::string(100000, 'x') + "=1"});
  CHECK(e.size() < 400);
}

TEST_CASE("print: --code refuses dimensions the sensor could not read back, saying which") {
  // widths: 0 < thin < thick < wide, each 0.25 mm apart at least (the sensor's halfway thresholds)
  CHECK(has(refusal({"thick=1.4", "wide=1.5"}),
            "--code thick=1.4 --code wide=1.5: wide 1.50 mm is not 0.25 mm wider than thick "
            "1.40 mm"));
  CHECK(has(refusal({"thick=0.6"}), "thick 0.60 mm is not 0.25 mm wider than thin 0.52 mm"));
  CHECK(has(refusal({"thin=2"}), "thick 1.31 mm is not 0.25 mm wider than thin 2.00 mm"));
  CHECK(has(refusal({"thin=0.2"}), "thin 0.20 mm is narrower than the 0.25 mm"));
  // along the row: strokes apart, 9 of them within a section
  CHECK(has(refusal({"stroke_length=16"}), "stroke_length 16.00 mm leaves less than 1.00 mm"));
  CHECK(has(refusal({"stroke_pitch=10"}), "stroke_length 9.90 mm leaves less than 1.00 mm"));
  CHECK(has(refusal({"stroke_length=1"}), "stroke_length 1.00 mm is shorter than 2.00 mm"));
  CHECK(has(refusal({"stroke_pitch=17"}),
            "stroke_pitch 17.00 mm: 9 strokes take 153.00 mm of a section's 150.00 mm, leaving "
            "less than 1.00 mm more between sections than between strokes for the reader to part "
            "them; make it at most 16.55 mm"));
  CHECK(has(refusal({"stroke_pitch=16.6"}), "make it at most 16.55 mm"));
  CHECK(code({"stroke_pitch=16.55"}).ok());
  // across the row: line and gap seen, the next row clear
  CHECK(has(refusal({"line_width=0.3"}), "line_width 0.30 mm is narrower than the 0.50 mm"));
  CHECK(has(refusal({"gap=0.2"}), "gap 0.20 mm is narrower than 0.40 mm"));
  CHECK(has(refusal({"gap=2.5"}), "gap 2.50 mm is wider than 2.00 mm"));
  CHECK(has(refusal({"wide=2.6"}),
            "a wide stroke reaches 4.04 mm from its line (line_width / 2 + gap + wide), more "
            "than 4.00 mm"));
  CHECK(has(refusal({"line_width=3"}), "a wide stroke reaches"));
}

TEST_CASE("print: the code dimensions go into a piece SVG's metadata and come back") {
  auto g = code({"thick=1.5", "stroke_pitch=16"});
  REQUIRE(g.ok());
  auto svg = print::pieceSvg(onePiece("S:60,len=300"), *g);
  REQUIRE(svg.ok());
  CHECK(has(*svg, "code-thick-mm=\"1.5000\""));
  CHECK(has(*svg, "code-stroke-pitch-mm=\"16.0000\""));
  CHECK(has(*svg, "code-thin-mm=\"0.5200\""));
  auto meta = print::readMetadata(*svg);
  REQUIRE(meta.ok());
  CHECK(meta->code.thick_mm == 1.5);
  CHECK(meta->code.stroke_pitch_mm == 16);
  CHECK(meta->code.wide_mm == sim::CodeGeometry{}.wide_mm);
}

TEST_CASE("print: an SVG without code dimensions (written before) reads with the defaults") {
  print::PieceSvg p{"S:60,len=300", 60, {324, 208, 20, 104}, {}};
  std::string svg = print::withMetadata("<svg width=\"324mm\" height=\"208mm\"></svg>", p);
  // leave out every code attribute, as an older pitwall wrote it
  for (auto at = svg.find(" code-"); at != std::string::npos; at = svg.find(" code-")) {
    const auto end = svg.find('"', svg.find('"', at) + 1);
    svg.erase(at, end + 1 - at);
  }
  REQUIRE_FALSE(has(svg, "code-"));
  auto meta = print::readMetadata(svg);
  REQUIRE(meta.ok());
  CHECK(print::codeDifferences(meta->code).empty());
}

TEST_CASE("print: an SVG whose code dimensions are no numbers or unreadable is refused") {
  print::PieceSvg p{"S:60,len=300", 60, {324, 208, 20, 104}, {}};
  const std::string svg = print::withMetadata("<svg width=\"324mm\"></svg>", p);
  std::string bad = svg;
  bad.replace(bad.find("code-thick-mm=\"1.3100\""), 22, "code-thick-mm=\"nan\"");
  auto meta = print::readMetadata(bad);
  REQUIRE_FALSE(meta.ok());
  CHECK(has(meta.error(), "no number code-thick-mm"));
  bad = svg;
  bad.replace(bad.find("code-thick-mm=\"1.3100\""), 22, "code-thick-mm=\"3.0000\"");
  meta = print::readMetadata(bad);
  REQUIRE_FALSE(meta.ok());
  CHECK(has(meta.error(), "code dimensions no sensor reads: wide 2.09 mm is not 0.25 mm wider"));
}

TEST_CASE(
    "print: a piece printed with --code thick=1.5 --code stroke_pitch=16 reads back from "
    "its SVG with the dimensions the SVG gives") {
  auto g = code({"thick=1.5", "stroke_pitch=16"});
  REQUIRE(g.ok());
  const sim::Piece piece = onePiece("S:60,len=300");
  auto svg = print::pieceSvg(piece, *g);
  REQUIRE(svg.ok());
  char name[] = "/tmp/pitwall-code-XXXXXX.svg";
  const int fd = mkstemps(name, 4);
  REQUIRE(fd >= 0);
  REQUIRE(write(fd, svg->data(), svg->size()) == static_cast<ssize_t>(svg->size()));
  close(fd);
  auto loaded = print::loadPieceSvg(name, 203.2);
  std::remove(name);
  REQUIRE(loaded.ok());
  const auto& [raster, meta] = *loaded;
  const auto result = print::readBack(raster, piece, meta.code);
  CHECK(result.ok());
  // Read with the default dimensions, the stroke spacing is off by 3 %: as a scaled page.
  CHECK_FALSE(print::readBack(raster, piece).ok());
}

TEST_CASE("print: pieces drawn at the limits --code allows read back as designed") {
  const std::vector<std::vector<std::string>> limits{
      {"thin=0.25", "thick=0.5", "wide=0.75"},  // the narrowest widths
      {"gap=0.4", "line_width=0.5"},            // the narrowest gap and line
      {"stroke_length=2"},                      // the shortest strokes
      {"stroke_pitch=16.55"},  // the longest pitch: 9 strokes and 1 mm fill a section
      {"stroke_pitch=12", "stroke_length=11"},           // strokes 1 mm apart
      {"wide=2.565"},                                    // the widest stroke, 4 mm out
      {"gap=2", "thin=0.4", "thick=0.8", "wide=1.345"},  // the widest gap
  };
  for (const auto& items : limits) {
    auto g = code(items);
    REQUIRE_MESSAGE(g.ok(), (g.ok() ? std::string() : g.error()));
    for (const std::string token : {"S:60,len=300", "L:61,r=400,deg=45"}) {
      CAPTURE(items.front());
      CAPTURE(token);
      const sim::Piece piece = onePiece(token);
      const auto result = print::readBack(print::renderPiece(piece, 8, *g), piece, *g);
      CHECK_MESSAGE(result.ok(), print::report(result, piece, "limit"));
    }
  }
}
