#pragma once
// Printing pieces (docs/cli.md "track print"): every piece of a PIECE token or a layout FILE,
// at 1:1, either as a PDF of paper-sized tiles that overlap (cut and alignment marks, a label and
// a 100 mm ruler on every page, so a user can check the printer did not scale it) or as one SVG
// sheet per piece carrying the metadata `track verify` reads back (svg_metadata.hpp).
// The tiling follows tragediy's idea (NoveroResearch/tragediy): a fixed unprintable margin, and
// neighbouring tiles repeating a strip of the drawing.
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/sim/code_layout.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::print {

struct Paper {
  std::string name;  // "A4", "A3"
  double width_mm = 0, height_mm = 0;
  double margin_mm = 5;   // unprintable on every side
  double overlap_mm = 5;  // repeated on neighbouring tiles
  double band_mm = 14;    // along the bottom: the page's label and its ruler, never the drawing
};
// "a4" or "a3", portrait unless `landscape`; an error sentence for another name.
Result<Paper, std::string> paperNamed(std::string_view name, bool landscape);

// How many tiles a sheet of `width_mm` × `height_mm` takes on `paper`: columns and rows.
struct Tiling {
  int columns = 1, rows = 1;
  double step_x_mm = 0, step_y_mm = 0;  // between the drawing windows of neighbouring tiles
  int pages() const { return columns * rows; }
};
Tiling tiling(double width_mm, double height_mm, const Paper& paper);

// The pieces `arg` names, as printed (a right curve as its left curve: the same piece, laid the
// other way round): a layout file (each piece in order), a piece token ("S", "L:17",
// "S:60,len=300", "start" = pieces 34 and 33), one of Anki's stock pieces by its id alone ("40"
// is S:40, "34" the start pair's first piece) or a layout name.
Result<std::vector<sim::Piece>, std::string> piecesOf(std::string_view arg);

// Writes every piece onto tiled pages of one PDF; the number of pages.
Result<int, std::string> writePdf(const std::string& path, const std::vector<sim::Piece>& pieces,
                                  const Paper& paper, const sim::CodeGeometry& g = {});
// One piece, whole, as an SVG sheet at 1:1 (width and height in mm) with its metadata.
Result<std::string, std::string> pieceSvg(const sim::Piece& piece, const sim::CodeGeometry& g = {});

}  // namespace pitwall::print
