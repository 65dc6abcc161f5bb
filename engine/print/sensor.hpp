#pragma once
// A model of the car's optical sensor reading a printed piece back (docs/cli.md "track verify"):
// it drives along every row's lane line in both directions over a raster (raster.hpp), takes
// the cross profile under it at each step, blurred as a lens blurs and a little off the line and
// askew as a car runs, finds the line, measures the dark stroke beside it on each side, groups
// the steps into strokes and the strokes into sections, and decodes each section
// (engine/protocol/anki/optical_code.hpp). Then it compares with the design: the piece id and
// location id of every section, and the stroke spacing (a page printed scaled reads wrong).
//
// Its figures are guesses, not measurements of a real car's sensor: documented in docs/tracks.md.
#include <string>
#include <string_view>
#include <vector>

#include "engine/print/raster.hpp"
#include "engine/sim/code_layout.hpp"

namespace pitwall::print {

struct SensorModel {
  double blur_mm = 0.25;          // σ of the Gaussian blur across the line
  double misalign_mm = 0.5;       // the sensor weaves up to this far beside the line
  double yaw_deg = 1.0;           // and looks across it this much askew
  double step_mm = 0.5;           // between readings along the row
  double sample_mm = 0.1;         // between samples across it
  double window_mm = 5.5;         // half the width it sees across the line
  double scale_tolerance = 0.01;  // stroke spacing off the design by more: "the page was scaled"
};

// One row driven in one direction.
struct RowPass {
  int row = 0;  // 0 = leftmost in the piece's forward direction
  bool reversed = false;
  int sections_designed = 0;
  int sections_read = 0;     // decoded to the designed ids, in the designed order
  double spacing_ratio = 1;  // measured stroke pitch ÷ designed, 1 when nothing was measured
  std::vector<anki::optical::Reading> readings;  // the sections that decoded, in driving order
  std::vector<std::string> problems;             // sentences, empty when the row reads as designed
};

struct ReadBack {
  std::vector<RowPass> passes;
  bool ok() const;
};

ReadBack readBack(const Raster& raster, const sim::Piece& piece, const sim::CodeGeometry& g = {},
                  const SensorModel& model = {});

// The report `track verify` prints: a line for each row and direction that does not read as
// designed (every one, OK or not, when `verbose`), then the verdict.
std::string report(const ReadBack& result, const sim::Piece& piece, std::string_view name,
                   bool verbose = false);

}  // namespace pitwall::print
