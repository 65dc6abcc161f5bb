#pragma once
// What a piece SVG written by `track print` says about itself, so `track verify` knows what it
// should read and where: the piece's token, the sheet (its size, and where the piece's start
// pose lies, heading along +x) and the stroke dimensions it was drawn with (code_options.hpp:
// `code-stroke-pitch-mm="16.5000"` …). Written as a <metadata> element, which renderers ignore.
#include <string>
#include <string_view>

#include "engine/core/result.hpp"
#include "engine/print/piece_drawing.hpp"
#include "engine/sim/code_layout.hpp"

namespace pitwall::print {

struct PieceSvg {
  std::string token;  // pieceName: "S:60,len=300", "start"
  int piece_id = 0;   // which piece of the token ("start" is two)
  Sheet sheet;
  // The code's dimensions; an SVG written before they were recorded: the defaults.
  sim::CodeGeometry code;
};

// `svg` (cairo's output) with the metadata element inserted after its <svg …> start tag.
std::string withMetadata(std::string_view svg, const PieceSvg& piece);
// The metadata of an SVG, or a sentence saying what is missing.
Result<PieceSvg, std::string> readMetadata(std::string_view svg);

}  // namespace pitwall::print
