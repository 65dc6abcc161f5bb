#pragma once
// A grey raster of a printed piece, as the sensor model (sensor.hpp) scans it: rendered in
// process from the drawing (the tests), or from an SVG that `track print` wrote, through librsvg
// at a printer's resolution (`track verify`). It knows where the piece lies on it: the sheet's
// origin (piece_drawing.hpp) as the drawing's metadata says, at the resolution it was rendered.
#include <cstdint>
#include <string>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/print/piece_drawing.hpp"
#include "engine/print/svg_metadata.hpp"

namespace pitwall::print {

struct Raster {
  int width = 0, height = 0;       // pixels
  double px_per_mm = 0;            // as intended: a scaled drawing still believes it is 1:1
  Sheet sheet;                     // where the piece lies, in mm from the top-left corner
  std::vector<std::uint8_t> dark;  // 0 white … 255 black, row by row

  // Darkness 0…1 at a sheet point (mm), bilinear between pixel centres; white outside.
  double darkness(double x_mm, double y_mm) const;
};

// The piece drawn at `px_per_mm` (tests: 8 px/mm reads back in a fraction of a second). `scale`
// ≠ 1 draws it larger or smaller about the sheet's top-left corner, as a printer that scales the
// page does, while the raster keeps believing it is 1:1.
Raster renderPiece(const sim::Piece& piece, double px_per_mm, const sim::CodeGeometry& g = {},
                   const DrawOptions& options = {}, double scale = 1.0);

// A piece SVG is refused unread above this size (`track print` writes well under 1 MB).
inline constexpr std::uint64_t kMaxSvgBytes = 16 * 1024 * 1024;

// What librsvg may spend on one SVG: it parses and draws it in a child process with its address
// space (beyond what this process maps) and CPU time limited, and at most twice the seconds in
// wall-clock time (track verify --draw-mb, --draw-seconds).
struct DrawLimits {
  int megabytes = 512;
  int seconds = 20;
};

// An SVG file rendered at `dpi` at the size its width and height say (as a printer would print
// it, scaled if they were changed), and its metadata; the raster's sheet is the metadata's. An
// error sentence names the file and says what to do. A file larger than kMaxSvgBytes, or one
// that declares XML entities, is refused before librsvg sees it; one that takes more than
// `limits` to draw is refused with a sentence that says which limit.
Result<std::pair<Raster, PieceSvg>, std::string> loadPieceSvg(const std::string& path, double dpi,
                                                              const DrawLimits& limits = {});

}  // namespace pitwall::print
