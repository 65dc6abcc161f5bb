#include "engine/print/code_options.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/core/printable.hpp"
#include "engine/core/suggest.hpp"

namespace pitwall::print {

namespace {

using G = sim::CodeGeometry;

constexpr std::array<CodeDimension, 7> kDimensions{{
    {"stroke_pitch", &G::stroke_pitch_mm},
    {"stroke_length", &G::stroke_length_mm},
    {"line_width", &G::line_width_mm},
    {"gap", &G::gap_mm},
    {"thin", &G::thin_mm},
    {"thick", &G::thick_mm},
    {"wide", &G::wide_mm},
}};

// Beyond this a value is a typo (a piece is 192 mm wide), not a calibration.
constexpr double kLargest = 50;
// The sensor model (sensor.hpp) sees 0.1 mm samples through a 0.25 mm blur and a printer at
// 300 dpi places dots 0.085 mm apart: widths nearer than this are not told apart reliably.
constexpr double kWidthStep = 0.25;
// Between two strokes along a row the sensor (0.5 mm steps) must see white at least twice.
constexpr double kStrokeSpace = 1;
// Sections are this much further apart than the strokes within one, at least.
constexpr double kSectionSpace = 1;
constexpr double kShortestStroke = 2;  // four steps: a stroke, not a speck
constexpr double kNarrowestLine = 0.5;
constexpr double kNarrowestGap = 0.4;  // the blur must leave white between line and stroke
// The reader tells rows apart by the white between them (sensor.cpp `acquire`: more than a
// quarter of the row pitch): neighbouring rows' strokes stay this much further apart than that.
constexpr double kRowMargin = 1;

std::string mm(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.2f mm", v);
  return buf;
}

std::string shown(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string known() {
  std::string out;
  for (const auto& d : kDimensions) out += (out.empty() ? "" : ", ") + std::string(d.name);
  return out;
}

std::optional<std::string> apply(G& g, std::string_view item) {
  const std::string what = "--code " + (item.empty() ? "''" : printable(item, 60));
  const auto eq = item.find('=');
  if (eq == std::string_view::npos)
    return what + " has no '=': give NAME=VALUE in mm, e.g. --code thick=1.4";
  const std::string_view name = item.substr(0, eq), value = item.substr(eq + 1);
  if (name.empty()) return what + " names no dimension: give NAME=VALUE in mm, one of " + known();
  if (name == "rows" || name == "row_pitch" || name == "section_min")
    return what + ": " + std::string(name) +
           " decides the location ids the simulator reports, so it stays as it is; --code "
           "changes the strokes only: " +
           known();
  const CodeDimension* dim = nullptr;
  for (const auto& d : kDimensions)
    if (d.name == name) dim = &d;
  if (!dim) {
    // "thick_mm" means thick: the struct's spelling.
    std::string_view bare = name;
    if (bare.size() > 3 && bare.substr(bare.size() - 3) == "_mm") bare.remove_suffix(3);
    std::vector<std::string> all;
    for (const auto& d : kDimensions) all.emplace_back(d.name);
    const auto guess = std::find(all.begin(), all.end(), bare) != all.end() ? std::string(bare)
                                                                            : nearest(bare, all);
    return what + ": unknown code dimension '" + printable(name, 40) + "'" +
           (guess ? " (did you mean " + *guess + "?)" : std::string()) + "; give one of " + known();
  }
  const std::string dimension(dim->name);
  const std::string example = " mm, e.g. --code " + dimension + "=" + shown(G{}.*(dim->field));
  double v = 0;
  const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
  if (value.empty() || ec == std::errc::invalid_argument || end != value.data() + value.size())
    return what + ": '" + printable(value, 40) + "' is not a number; give " + dimension + " in" +
           example;
  if (std::isnan(v))
    return what + ": '" + printable(value, 40) + "' is not a number; give " + dimension + " in" +
           example;
  if (ec == std::errc::result_out_of_range || !std::isfinite(v) || v > kLargest)
    return what + ": " + dimension + " " + printable(value, 40) + " is beyond " + shown(kLargest) +
           " mm; give it in" + example;
  if (v <= 0) return what + ": " + dimension + " must be more than 0; give it in" + example;
  g.*(dim->field) = v;
  return std::nullopt;
}

}  // namespace

std::span<const CodeDimension> codeDimensions() {
  return kDimensions;
}

std::optional<std::string> codeProblem(const G& g) {
  for (const auto& d : kDimensions) {
    const double v = g.*(d.field);
    if (!std::isfinite(v) || v <= 0 || v > kLargest)
      return std::string(d.name) + " " + shown(v) + " is not between 0 and " + shown(kLargest) +
             " mm";
  }
  if (g.thin_mm < kWidthStep)
    return "thin " + mm(g.thin_mm) + " is narrower than the " + mm(kWidthStep) +
           " the sensor tells from no stroke; make thin at least that";
  if (g.thick_mm < g.thin_mm + kWidthStep)
    return "thick " + mm(g.thick_mm) + " is not " + mm(kWidthStep) + " wider than thin " +
           mm(g.thin_mm) + ", so the sensor cannot tell a 1 from a 0; make thick at least " +
           mm(g.thin_mm + kWidthStep) + " or thin narrower";
  if (g.wide_mm < g.thick_mm + kWidthStep)
    return "wide " + mm(g.wide_mm) + " is not " + mm(kWidthStep) + " wider than thick " +
           mm(g.thick_mm) + ", so the sensor cannot tell a boundary from a 1; make wide at least " +
           mm(g.thick_mm + kWidthStep) + " or thick narrower";
  if (g.line_width_mm < kNarrowestLine)
    return "line_width " + mm(g.line_width_mm) + " is narrower than the " + mm(kNarrowestLine) +
           " the sensor follows; make it at least that";
  if (g.gap_mm < kNarrowestGap)
    return "gap " + mm(g.gap_mm) + " is narrower than " + mm(kNarrowestGap) +
           ": the sensor's blur joins the stroke to the line; make it at least that";
  if (g.gap_mm > g.row_pitch_mm / 4 - kRowMargin)
    return "gap " + mm(g.gap_mm) + " is wider than " + mm(g.row_pitch_mm / 4 - kRowMargin) +
           ": the reader would take the strokes for a row of their own; make it at most that";
  if (g.stroke_length_mm < kShortestStroke)
    return "stroke_length " + mm(g.stroke_length_mm) + " is shorter than " + mm(kShortestStroke) +
           ", a speck to the sensor; make it at least that";
  if (g.stroke_length_mm > g.stroke_pitch_mm - kStrokeSpace)
    return "stroke_length " + mm(g.stroke_length_mm) + " leaves less than " + mm(kStrokeSpace) +
           " between strokes " + mm(g.stroke_pitch_mm) +
           " apart (stroke_pitch), so they run together; make it at most " +
           mm(g.stroke_pitch_mm - kStrokeSpace) + " or stroke_pitch larger";
  // 9 strokes fit a section, with more space between sections than between strokes: the
  // reader (sensor.cpp `sections`) cuts sections where the strokes are further apart.
  const double most = (g.section_min_mm - kSectionSpace) / anki::optical::kStrokes;
  if (g.stroke_pitch_mm > most + 1e-9)
    return "stroke_pitch " + mm(g.stroke_pitch_mm) + ": 9 strokes take " +
           mm(anki::optical::kStrokes * g.stroke_pitch_mm) + " of a section's " +
           mm(g.section_min_mm) + ", leaving less than " + mm(kSectionSpace) +
           " more between sections than between strokes for the reader to part them; make it at "
           "most " +
           mm(std::floor(most * 100) / 100);
  const double outer = g.innerEdge() + g.wide_mm;
  const double limit = g.row_pitch_mm / 2 - g.row_pitch_mm / 8 - kRowMargin / 2;
  if (outer > limit + 1e-9)
    return "a wide stroke reaches " + mm(outer) + " from its line (line_width / 2 + gap + wide), " +
           "more than " + mm(limit) + ": too near the next row's strokes " + mm(g.row_pitch_mm) +
           " away for the reader to tell rows apart; make line_width, gap " + "or wide smaller";
  return std::nullopt;
}

Result<G, std::string> withOverrides(G g, std::span<const std::string> overrides) {
  for (const std::string& item : overrides)
    if (auto problem = apply(g, item)) return Unexpected<std::string>(*problem);
  if (auto problem = codeProblem(g)) {
    std::string given;
    for (const std::string& item : overrides)
      given += (given.empty() ? "" : " ") + ("--code " + printable(item, 60));
    return Unexpected<std::string>(given + ": " + *problem);
  }
  return g;
}

std::string codeDifferences(const G& g) {
  const G defaults;
  std::string out;
  for (const auto& d : kDimensions)
    if (g.*(d.field) != defaults.*(d.field))
      out += (out.empty() ? "" : ", ") + std::string(d.name) + " " + mm(g.*(d.field));
  return out;
}

}  // namespace pitwall::print
