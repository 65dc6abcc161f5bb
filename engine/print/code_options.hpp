#pragma once
// `--code NAME=VALUE` (docs/cli.md "track print"): the stroke dimensions of the optical code a
// user with a real car calibrates, over sim::CodeGeometry's defaults. Only the strokes: rows,
// row_pitch and section_min decide the location ids the simulator reports, so they stay fixed.
// Every value is checked on its own (a number of mm, 0 < v ≤ 50) and the whole against what the
// sensor model (sensor.hpp) needs to read it back; a problem is one sentence naming the
// dimension, its value and what to do.
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "engine/core/result.hpp"
#include "engine/sim/code_layout.hpp"

namespace pitwall::print {

// One dimension `--code` may change: its name on the command line and in the SVG metadata
// (`code-NAME-mm`, '_' written '-'), and the field.
struct CodeDimension {
  std::string_view name;  // "stroke_pitch"
  double sim::CodeGeometry::*field;
};
// stroke_pitch, stroke_length, line_width, gap, thin, thick, wide: in that order.
std::span<const CodeDimension> codeDimensions();

// `g` with each `NAME=VALUE` applied in order (a name given twice: the last value wins), then
// checked as a whole (codeProblem); the first problem as a sentence naming `--code NAME=VALUE`.
Result<sim::CodeGeometry, std::string> withOverrides(sim::CodeGeometry g,
                                                     std::span<const std::string> overrides);

// Why the sensor could not read strokes of these dimensions back, or nothing. A sentence.
std::optional<std::string> codeProblem(const sim::CodeGeometry& g);

// The dimensions that differ from the defaults, "thick 1.40 mm, stroke_pitch 16.00 mm"; "" when
// none does.
std::string codeDifferences(const sim::CodeGeometry& g);

}  // namespace pitwall::print
