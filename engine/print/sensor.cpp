#include "engine/print/sensor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

namespace pitwall::print {

namespace {

namespace optical = anki::optical;
using optical::Width;

constexpr double kThreshold = 0.5;  // dark enough to be a mark (of 0 white … 1 black)
// The reader looks for a row's line from this far outside the piece (a fraction of its length
// and mm): a page printed a few % too large reaches past the design's ends.
constexpr double kBeyond = 0.06, kBeyondMm = 5;
constexpr double kLineEndMm = 3;  // no line for this far: it ended

// A dark run of a profile: where it crosses the threshold on either side, in mm.
struct Run {
  double from = 0, to = 0;
  double centre() const { return (from + to) / 2; }
  double width() const { return to - from; }
};

// The cross profile under the sensor: darkness at `count` points `sample_mm` apart, centred on
// the sensor, blurred.
class Profile {
 public:
  Profile(const SensorModel& m) : m_(m) {
    count_ = 2 * static_cast<int>(std::round(m.window_mm / m.sample_mm)) + 1;
    raw_.resize(static_cast<std::size_t>(count_));
    values_.resize(static_cast<std::size_t>(count_));
    const double sigma = m.blur_mm / m.sample_mm;
    if (sigma > 0.05) {
      const int radius = static_cast<int>(std::ceil(3 * sigma));
      double sum = 0;
      for (int i = -radius; i <= radius; ++i) {
        kernel_.push_back(std::exp(-0.5 * i * i / (sigma * sigma)));
        sum += kernel_.back();
      }
      for (double& k : kernel_) k /= sum;
    } else {
      kernel_ = {1.0};
    }
  }

  // Samples across the line at point (x, y) of the piece frame, along direction (dx, dy).
  void take(const Raster& r, double x, double y, double dx, double dy) {
    const int half = count_ / 2;
    for (int i = 0; i < count_; ++i) {
      const double u = (i - half) * m_.sample_mm;
      raw_[static_cast<std::size_t>(i)] =
          r.darkness(r.sheet.sheetX(x + u * dx), r.sheet.sheetY(y + u * dy));
    }
    const int radius = static_cast<int>(kernel_.size()) / 2;
    for (int i = 0; i < count_; ++i) {
      double v = 0;
      for (int k = -radius; k <= radius; ++k) {
        const int j = std::clamp(i + k, 0, count_ - 1);
        v += kernel_[static_cast<std::size_t>(k + radius)] * raw_[static_cast<std::size_t>(j)];
      }
      values_[static_cast<std::size_t>(i)] = v;
    }
  }

  double u(double i) const { return (i - count_ / 2) * m_.sample_mm; }

  std::vector<Run> runs() const {
    std::vector<Run> out;
    bool open = false;
    double from = 0;
    for (int i = 0; i < count_; ++i) {
      const bool dark = at(i) >= kThreshold;
      if (dark && !open) from = i == 0 ? u(0) : u(crossing(i - 1, i)), open = true;
      if (!dark && open) {
        out.push_back({from, u(crossing(i - 1, i))});
        open = false;
      }
    }
    if (open) out.push_back({from, u(count_ - 1)});
    return out;
  }

  // The darkness between lateral positions a < b (mm): a mark's width, kept by the blur.
  double area(double a, double b) const {
    const int half = count_ / 2;
    const int i0 = std::max(0, static_cast<int>(std::ceil(a / m_.sample_mm)) + half);
    const int i1 = std::min(count_ - 1, static_cast<int>(std::floor(b / m_.sample_mm)) + half);
    double sum = 0;
    for (int i = i0; i <= i1; ++i) sum += at(i);
    return sum * m_.sample_mm;
  }

 private:
  double at(int i) const { return values_[static_cast<std::size_t>(i)]; }
  double crossing(int i, int j) const {  // where the threshold lies between samples i and j
    const double a = at(i), b = at(j);
    return a == b ? i : i + (kThreshold - a) / (b - a);
  }

  const SensorModel& m_;
  int count_ = 0;
  std::vector<double> raw_, values_, kernel_;
};

// A reading beside the line at one step, in the reader's frame.
struct Step {
  // How far the sensor has followed the line (mm): measured on the page, not taken from the
  // design, so a scaled page shows in the spacing of its strokes, on a curve as on a straight.
  double travelled = 0;
  bool line = false;
  double dark = 0;  // the darkness beside the line, both sides (mm): weights a stroke's centre
  optical::Stroke stroke;
};

struct StrokeSeen {
  double centre = 0;  // along the row, mm
  optical::Stroke stroke;
};

Width classify(double width, const sim::CodeGeometry& g) {
  if (width < g.thin_mm / 2) return Width::None;
  if (width < (g.thin_mm + g.thick_mm) / 2) return Width::Thin;
  if (width < (g.thick_mm + g.wide_mm) / 2) return Width::Thick;
  return Width::Wide;
}

// Where the reader starts: the first place, coming from outside the piece, where a look across
// the road finds every row's line and nothing else between them — as a car is put on the track
// before the piece. A page printed scaled has its lines off their design and its ends moved;
// finding them all at once keeps each reader on its own row. Found nowhere: the design's places.
struct Start {
  double fraction = 0;        // along the piece
  std::vector<double> delta;  // each row's line, lateral from its design offset (mm)
};

Start acquire(const Raster& raster, const sim::Piece& piece, const sim::CodeLayout& layout,
              const sim::CodeGeometry& g, const SensorModel& m, bool reversed) {
  Start start{reversed ? 1.0 : 0.0, std::vector<double>(layout.rows.size(), 0.0)};
  SensorModel wide = m;
  wide.window_mm = roadHalfWidth(g) + 6;
  Profile profile(wide);
  const double length = piece.length(0);
  const double beyond = kBeyond + kBeyondMm / length, step = 1.5 / length;
  for (double f = -beyond; f < 0.5; f += step) {
    const double at = reversed ? 1 - f : f;
    const sim::Pose p = sim::poseOnPiece(piece, {}, at, 0);
    const double h = p.heading * std::numbers::pi / 180;
    profile.take(raster, p.x, p.y, std::sin(h), -std::cos(h));
    // Runs closer than a row's gap between its strokes and the next row's belong to one row.
    std::vector<std::vector<Run>> clusters;
    for (const Run& r : profile.runs()) {
      if (r.width() < g.thin_mm / 3) continue;
      if (clusters.empty() || r.from - clusters.back().back().to > g.row_pitch_mm / 4)
        clusters.emplace_back();
      clusters.back().push_back(r);
    }
    if (clusters.size() != layout.rows.size()) continue;
    std::vector<double> lines;
    for (const auto& c : clusters) {
      if (c.size() == 1)
        lines.push_back(c[0].centre());
      else if (c.size() == 3)
        lines.push_back(c[1].centre());  // a stroke either side
      else
        break;
    }
    if (lines.size() != clusters.size()) continue;
    // Lines evenly spaced, about a row pitch apart: rows, not a label's letters.
    bool even = true;
    for (std::size_t i = 1; i < lines.size(); ++i)
      even = even && std::abs(lines[i] - lines[i - 1] - g.row_pitch_mm) < 0.1 * g.row_pitch_mm;
    if (!even) continue;
    start.fraction = at;
    for (std::size_t i = 0; i < lines.size(); ++i)
      start.delta[i] = lines[i] - layout.rows[i].offset_mm;
    return start;
  }
  return start;
}

// Drives one row in one direction from `start` until its line ends; the steps in driving order.
std::vector<Step> drive(const Raster& raster, const sim::Piece& piece, const sim::CodeRow& row,
                        double fraction, double delta, const sim::CodeGeometry& g,
                        const SensorModel& m, bool reversed) {
  Profile profile(m);
  const double yaw = (reversed ? -1 : 1) * m.yaw_deg * std::numbers::pi / 180;
  const double gapMid = g.line_width_mm / 2 + g.gap_mm / 2;  // from the line's centre
  const double reach = g.innerEdge() + g.wide_mm + 3 * m.blur_mm + 0.3;
  const double beyond = kBeyond + kBeyondMm / row.length_mm;
  std::vector<Step> steps;
  double travelled = 0, last_x = 0, last_y = 0, lost = 0;
  bool seen = false;
  for (double s = fraction * row.length_mm;
       s >= -beyond * row.length_mm && s <= (1 + beyond) * row.length_mm;
       s += reversed ? -m.step_mm : m.step_mm) {
    Step st;
    // The sensor weaves beside the line, up to misalign_mm either way.
    const double weave = m.misalign_mm * std::sin(2 * std::numbers::pi * s / 97.0);
    const double centre = row.offset_mm + delta + weave;
    const sim::Pose p = sim::poseOnPiece(piece, {}, s / row.length_mm, centre);
    const double h = p.heading * std::numbers::pi / 180 + yaw;
    const double dx = std::sin(h), dy = -std::cos(h);
    profile.take(raster, p.x, p.y, dx, dy);
    // The line: the run nearest where the sensor believes it is.
    std::optional<Run> line;
    for (const Run& r : profile.runs())
      if (std::abs(r.centre() + weave) < 1.0 && r.width() > g.line_width_mm / 3 &&
          (!line || std::abs(r.centre() + weave) < std::abs(line->centre() + weave)))
        line = r;
    if (line) {
      st.line = true;
      lost = 0;
      const double c = line->centre();
      delta += c + weave;                               // follow the line, as the car steers
      const double x = p.x + c * dx, y = p.y + c * dy;  // on the line
      travelled += seen ? std::hypot(x - last_x, y - last_y) : 0;
      last_x = x, last_y = y, seen = true;
      const double left = profile.area(c - reach, c - gapMid);
      const double right = profile.area(c + gapMid, c + reach);
      st.dark = left + right;
      const Width minus = classify(left, g);
      const Width plus = classify(right, g);
      // Forward the reader's left is the design's left (−); driven back, it is the right.
      st.stroke = reversed ? optical::Stroke{plus, minus} : optical::Stroke{minus, plus};
    } else {
      travelled += m.step_mm;  // lost: as far as the sensor moved
      lost += m.step_mm;
      if (lost > kLineEndMm) break;  // the line ended (or is gone): the car stops reading
    }
    st.travelled = travelled;
    steps.push_back(st);
  }
  // What was driven past the line's end is not part of it.
  while (!steps.empty() && !steps.back().line) steps.pop_back();
  return steps;
}

Width mode(const std::vector<Width>& ws) {
  int count[4] = {};
  for (Width w : ws) ++count[static_cast<int>(w)];
  return static_cast<Width>(std::max_element(count, count + 4) - count);
}

std::vector<StrokeSeen> strokes(const std::vector<Step>& steps, const sim::CodeGeometry& g,
                                const SensorModel& m) {
  std::vector<StrokeSeen> out;
  std::size_t i = 0;
  auto marked = [](const Step& s) {
    return s.line && (s.stroke.left != Width::None || s.stroke.right != Width::None);
  };
  while (i < steps.size()) {
    if (!marked(steps[i])) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < steps.size() && marked(steps[j])) ++j;
    const double length = (j - i) * m.step_mm;
    if (length >= 0.3 * g.stroke_length_mm) {
      // Its width on each side: what most steps saw, leaving out the ends (partly on the stroke).
      const std::size_t trim = j - i >= 4 ? 1 : 0;
      std::vector<Width> left, right;
      for (std::size_t k = i + trim; k < j - trim; ++k)
        left.push_back(steps[k].stroke.left), right.push_back(steps[k].stroke.right);
      // Its centre: the darkness-weighted mean of where it was seen, with the steps just
      // before and after (partly on it), finer than a step.
      double sum = 0, weight = 0;
      for (std::size_t k = i > 0 ? i - 1 : i; k < std::min(j + 1, steps.size()); ++k)
        if (steps[k].line) sum += steps[k].travelled * steps[k].dark, weight += steps[k].dark;
      out.push_back({sum / weight, {mode(left), mode(right)}});
    }
    i = j;
  }
  return out;
}

// The strokes cut into sections: a gap between strokes wider than between a section's own
// strokes (as measured, so a scaled page still cuts right) ends one.
std::vector<std::vector<StrokeSeen>> sections(const std::vector<StrokeSeen>& seen,
                                              const sim::CodeGeometry& g) {
  std::vector<std::vector<StrokeSeen>> out;
  if (seen.empty()) return out;
  std::vector<double> gaps;
  for (std::size_t i = 1; i < seen.size(); ++i)
    gaps.push_back(std::abs(seen[i].centre - seen[i - 1].centre));
  double pitch = g.stroke_pitch_mm;
  if (!gaps.empty()) {
    std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
    pitch = gaps[gaps.size() / 2];
  }
  // Sections are at least section_min_mm long, so between two of them the strokes are at least
  // this far apart; cut half way between that and the pitch.
  const double between = g.section_min_mm - (optical::kStrokes - 1) * g.stroke_pitch_mm;
  const double cut = pitch * (1 + between / g.stroke_pitch_mm) / 2;
  out.emplace_back();
  for (std::size_t i = 0; i < seen.size(); ++i) {
    if (i > 0 && std::abs(seen[i].centre - seen[i - 1].centre) > cut) out.emplace_back();
    out.back().push_back(seen[i]);
  }
  // Runs of whole sections the cut did not part (a geometry whose sections touch): by nine.
  std::vector<std::vector<StrokeSeen>> split;
  for (auto& s : out) {
    if (s.size() > optical::kStrokes && s.size() % optical::kStrokes == 0) {
      for (std::size_t k = 0; k < s.size(); k += optical::kStrokes)
        split.emplace_back(s.begin() + static_cast<long>(k),
                           s.begin() + static_cast<long>(k + optical::kStrokes));
    } else {
      split.push_back(std::move(s));
    }
  }
  return split;
}

std::string percent(double ratio) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.1f %%", std::abs(ratio - 1) * 100);
  return buf;
}

RowPass readRow(const Raster& raster, const sim::Piece& piece, const sim::CodeLayout& layout, int r,
                double fraction, double delta, const sim::CodeGeometry& g, const SensorModel& m,
                bool reversed) {
  const sim::CodeRow& row = layout.rows[static_cast<std::size_t>(r)];
  RowPass pass;
  pass.row = r;
  pass.reversed = reversed;
  pass.sections_designed = row.sections;
  const auto steps = drive(raster, piece, row, fraction, delta, g, m, reversed);
  // The line, followed from where the reader found it, should run the row's whole length.
  const double followed = steps.empty() ? 0 : steps.back().travelled;
  if (followed < 0.9 * row.length_mm)
    pass.problems.push_back("lost the line after " + std::to_string(static_cast<int>(followed)) +
                            " mm of its " + std::to_string(static_cast<int>(row.length_mm)) +
                            " mm");
  const auto found = sections(strokes(steps, g, m), g);

  // The spacing of each whole section's strokes against the design: a scaled page.
  double sum = 0;
  int whole = 0;
  for (const auto& s : found)
    if (s.size() == optical::kStrokes) {
      sum += std::abs(s.back().centre - s.front().centre) / (optical::kStrokes - 1);
      ++whole;
    }
  if (whole > 0) {
    pass.spacing_ratio = sum / whole / g.stroke_pitch_mm;
    if (std::abs(pass.spacing_ratio - 1) > m.scale_tolerance)
      pass.problems.push_back("strokes " + percent(pass.spacing_ratio) +
                              (pass.spacing_ratio > 1 ? " further apart" : " closer together") +
                              " than designed: the page was scaled; print at actual size (100 %)");
  }

  if (static_cast<int>(found.size()) != row.sections)
    pass.problems.push_back("found " + std::to_string(found.size()) +
                            " sections where the design has " + std::to_string(row.sections));
  for (std::size_t k = 0; k < found.size() && k < static_cast<std::size_t>(row.sections); ++k) {
    const int designed = reversed ? row.sections - 1 - static_cast<int>(k) : static_cast<int>(k);
    const int location = row.locationOf(designed);
    std::vector<optical::Stroke> marks;
    for (const auto& s : found[k]) marks.push_back(s.stroke);
    const std::string where = "section " + std::to_string(designed + 1) + " (piece " +
                              std::to_string(piece.id) + ", location " + std::to_string(location) +
                              ")";
    auto reading = optical::decodeSection(marks);
    if (!reading) {
      pass.problems.push_back(where + ": " + reading.error());
      continue;
    }
    pass.readings.push_back(*reading);
    if (reading->piece_id != piece.id || reading->location_id != location ||
        reading->reversed != reversed) {
      pass.problems.push_back(
          where + ": read piece " + std::to_string(reading->piece_id) + ", location " +
          std::to_string(reading->location_id) +
          (reading->reversed != reversed ? ", as if driven the other way" : ""));
      continue;
    }
    ++pass.sections_read;
  }
  return pass;
}

}  // namespace

bool ReadBack::ok() const {
  return !passes.empty() &&
         std::all_of(passes.begin(), passes.end(), [](auto& p) { return p.problems.empty(); });
}

ReadBack readBack(const Raster& raster, const sim::Piece& piece, const sim::CodeGeometry& g,
                  const SensorModel& model) {
  ReadBack out;
  const sim::CodeLayout layout = sim::codeLayout(piece, g);
  for (bool reversed : {false, true}) {
    const Start start = acquire(raster, piece, layout, g, model, reversed);
    for (int r = 0; r < static_cast<int>(layout.rows.size()); ++r)
      out.passes.push_back(readRow(raster, piece, layout, r, start.fraction,
                                   start.delta[static_cast<std::size_t>(r)], g, model, reversed));
  }
  std::stable_sort(out.passes.begin(), out.passes.end(),
                   [](auto& a, auto& b) { return a.row < b.row; });
  return out;
}

std::string report(const ReadBack& result, const sim::Piece& piece, std::string_view name,
                   bool verbose) {
  std::string out;
  int sections = 0, failed = 0;
  for (const RowPass& p : result.passes) {
    sections += p.sections_designed;
    std::string head = std::string(name) + ": row " + std::to_string(p.row + 1) +
                       (p.reversed ? " backward: " : " forward:  ");
    if (p.problems.empty()) {
      if (verbose)
        out += head + "OK, " + std::to_string(p.sections_read) +
               (p.sections_read == 1 ? " section\n" : " sections\n");
      continue;
    }
    ++failed;
    for (const std::string& problem : p.problems) out += head + problem + "\n";
  }
  const std::string what = pieceName(piece) + " (piece " + std::to_string(piece.id) + ")";
  if (result.ok())
    out += std::string(name) + ": OK: " + what + ", " + std::to_string(sections) +
           " section readings on " + std::to_string(result.passes.size() / 2) +
           " rows in both directions all decode to the design\n";
  else
    out += std::string(name) + ": FAILED: " + what + ", " + std::to_string(failed) + " of " +
           std::to_string(result.passes.size()) +
           " row readings (rows counted from the left, driving forward) differ from the design\n";
  return out;
}

}  // namespace pitwall::print
