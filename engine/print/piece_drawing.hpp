#pragma once
// One piece drawn at 1:1 on a cairo context whose user unit is the millimetre (docs/cli.md
// "track print"): the road outline, every row's lane line and every section's strokes on both
// sides of it (engine/sim/code_layout.hpp), and a label outside the road. All geometry comes from
// sim::poseOnPiece, so the printout, the simulator and the race view agree.
//
// The drawing's frame is a sheet: mm from its top-left corner, x to the right, y down. The piece
// lies with its start pose at `Sheet::origin_*` heading along +x (the piece frame's y up is the
// sheet's y down), so its forward direction reads left to right.
#include <cairo.h>

#include <optional>
#include <string>

#include "engine/sim/code_layout.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::print {

// The token that names a piece: sim::pieceToken's, but "start" for either start piece (a start
// piece is only ever written as the pair; `part` tells which: 1 = piece 34, 2 = piece 33).
std::string pieceName(const sim::Piece& piece);

// Half the road's width: 16 rows 12 mm apart fill ±96 mm (code_layout.hpp).
double roadHalfWidth(const sim::CodeGeometry& g);

// The sheet a piece is drawn on: its size and where the piece's start pose lies on it.
struct Sheet {
  double width_mm = 0, height_mm = 0;
  double origin_x_mm = 0, origin_y_mm = 0;
  // A point of the piece frame (x right, y up, mm; start pose at 0,0 heading 0) on the sheet.
  double sheetX(double x) const { return origin_x_mm + x; }
  double sheetY(double y) const { return origin_y_mm - y; }
};
Sheet sheetFor(const sim::Piece& piece, const sim::CodeGeometry& g = {});

// One stroke on one side of a row's line: what a test leaves out to see the read-back fail.
struct StrokeRef {
  int row = 0;       // 0 = the leftmost row in the forward direction
  int section = 0;   // along the row, forward
  int stroke = 0;    // 0…8 within the section, forward
  bool left = true;  // the piece side
};

// A part of the sheet (mm): a PDF tile draws only the strokes that reach into its window, so a
// large piece's pages do not each carry all of it.
struct Window {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

struct DrawOptions {
  bool label = true;
  std::optional<StrokeRef> omit;  // leave this stroke white
  std::optional<Window> window;   // draw only the strokes that reach into it
};

// Draws `piece` in sheet coordinates (the context's user space: mm, y down).
void drawPiece(cairo_t* cr, const sim::Piece& piece, const Sheet& sheet,
               const sim::CodeGeometry& g = {}, const DrawOptions& options = {});

}  // namespace pitwall::print
