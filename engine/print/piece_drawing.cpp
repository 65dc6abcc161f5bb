#include "engine/print/piece_drawing.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace pitwall::print {

namespace {

namespace optical = anki::optical;

constexpr double kLabelStripMm = 16;  // before the piece's start edge, off every row
constexpr double kPadMm = 4;          // around the road and the label
constexpr double kTickMm = 4;         // the start and end edges' cut ticks, outside the road

struct Drawer {
  cairo_t* cr;
  const sim::Piece& piece;
  const Sheet& sheet;

  void point(double f, double offset, bool line) const {
    const sim::Pose p = sim::poseOnPiece(piece, {}, f, offset);
    (line ? cairo_line_to : cairo_move_to)(cr, sheet.sheetX(p.x), sheet.sheetY(p.y));
  }
  // A band between two offsets from fraction f0 to f1, as a closed path: a rectangle on a
  // straight, an annulus sector on a curve (sampled finely enough that a chord strays < 1 µm).
  void band(double f0, double f1, double offset_a, double offset_b) const {
    const int n = piece.turn == 0
                      ? 1
                      : std::max(2, static_cast<int>(std::ceil((f1 - f0) * piece.angle() * 4)));
    for (int i = 0; i <= n; ++i) point(f0 + (f1 - f0) * i / n, offset_a, i > 0);
    for (int i = n; i >= 0; --i) point(f0 + (f1 - f0) * i / n, offset_b, true);
    cairo_close_path(cr);
  }
  // Whether a stroke between f0 and f1 beside `offset` may reach into `w`: its ends and middle
  // on the line, with room for its width and the arc's bulge.
  bool reaches(double f0, double f1, double offset, const Window& w) const {
    constexpr double kRoom = 8;
    for (double f : {f0, (f0 + f1) / 2, f1}) {
      const sim::Pose p = sim::poseOnPiece(piece, {}, f, offset);
      const double x = sheet.sheetX(p.x), y = sheet.sheetY(p.y);
      if (x > w.x0 - kRoom && x < w.x1 + kRoom && y > w.y0 - kRoom && y < w.y1 + kRoom) return true;
    }
    return false;
  }
  void line(double f0, double f1, double offset) const {
    const int n = piece.turn == 0
                      ? 1
                      : std::max(2, static_cast<int>(std::ceil((f1 - f0) * piece.angle() * 4)));
    for (int i = 0; i <= n; ++i) point(f0 + (f1 - f0) * i / n, offset, i > 0);
  }
};

void drawLabel(cairo_t* cr, const sim::Piece& piece, const Sheet& sheet, double half) {
  cairo_save(cr);
  cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
  // The forward arrow at the road's centre, pointing into the piece.
  const double y = sheet.origin_y_mm, x0 = sheet.origin_x_mm - kLabelStripMm + 2,
               x1 = sheet.origin_x_mm - 2;
  cairo_set_line_width(cr, 0.6);
  cairo_move_to(cr, x0, y);
  cairo_line_to(cr, x1 - 2, y);
  cairo_stroke(cr);
  cairo_move_to(cr, x1, y);
  cairo_line_to(cr, x1 - 3, y - 1.6);
  cairo_line_to(cr, x1 - 3, y + 1.6);
  cairo_close_path(cr);
  cairo_fill(cr);
  // Text along the start edge, reading bottom to top: the token above the arrow, the reading
  // direction below it.
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 3.5);
  auto text = [&](double x, double from_y, const std::string& s) {
    cairo_save(cr);
    cairo_move_to(cr, x, from_y);
    cairo_rotate(cr, -std::numbers::pi / 2);
    cairo_show_text(cr, s.c_str());
    cairo_restore(cr);
  };
  const double x = sheet.origin_x_mm - kLabelStripMm / 2 + 1.2;
  text(x, y - 6, pieceName(piece) + "  (piece " + std::to_string(piece.id) + ")");
  text(x, y + std::min(half, 70.0), "forward: left to right");
  cairo_restore(cr);
}

}  // namespace

std::string pieceName(const sim::Piece& piece) {
  return sim::pieceToken(piece);  // "start" for either start piece
}

double roadHalfWidth(const sim::CodeGeometry& g) {
  return g.rows * g.row_pitch_mm / 2;
}

Sheet sheetFor(const sim::Piece& piece, const sim::CodeGeometry& g) {
  const double half = roadHalfWidth(g) + kTickMm;
  double minx = -kLabelStripMm, maxx = 0, miny = -half, maxy = half;
  for (int i = 0; i <= 128; ++i)
    for (double o : {-half, half}) {
      const sim::Pose p = sim::poseOnPiece(piece, {}, i / 128.0, o);
      minx = std::min(minx, p.x), maxx = std::max(maxx, p.x);
      miny = std::min(miny, p.y), maxy = std::max(maxy, p.y);
    }
  Sheet s;
  s.width_mm = std::ceil(maxx - minx + 2 * kPadMm);
  s.height_mm = std::ceil(maxy - miny + 2 * kPadMm);
  s.origin_x_mm = kPadMm - minx;
  s.origin_y_mm = kPadMm + maxy;
  return s;
}

void drawPiece(cairo_t* cr, const sim::Piece& piece, const Sheet& sheet, const sim::CodeGeometry& g,
               const DrawOptions& options) {
  const Drawer d{cr, piece, sheet};
  const double half = roadHalfWidth(g);
  cairo_save(cr);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_MITER);

  // The road's outline: its sides, and its ends as light lines with darker cut ticks outside
  // the road (light enough that a reader's threshold never takes them for a mark).
  cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
  cairo_set_line_width(cr, 0.25);
  for (double o : {-half, half}) {
    d.line(0, 1, o);
    cairo_stroke(cr);
  }
  for (double f : {0.0, 1.0})
    for (double o : {-half, half}) {
      d.point(f, o, false);
      d.point(f, o + (o < 0 ? -kTickMm : kTickMm), true);
      cairo_stroke(cr);
    }
  cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
  cairo_set_line_width(cr, 0.15);
  for (double f : {0.0, 1.0}) {
    d.point(f, -half, false);
    d.point(f, half, true);
    cairo_stroke(cr);
  }

  // The code: every row's line, and every section's strokes on both sides of it.
  cairo_set_source_rgb(cr, 0, 0, 0);
  const sim::CodeLayout layout = sim::codeLayout(piece, g);
  const double inner = g.innerEdge();
  for (std::size_t r = 0; r < layout.rows.size(); ++r) {
    const sim::CodeRow& row = layout.rows[r];
    d.band(0, 1, row.offset_mm - g.line_width_mm / 2, row.offset_mm + g.line_width_mm / 2);
    for (int k = 0; k < row.sections; ++k) {
      const auto strokes = optical::encodeSection(piece.id, row.locationOf(k));
      const auto centres = sim::strokeCentres(row, k, g);
      for (int j = 0; j < optical::kStrokes; ++j) {
        const double c = centres[static_cast<std::size_t>(j)];
        const double f0 = (c - g.stroke_length_mm / 2) / row.length_mm;
        const double f1 = (c + g.stroke_length_mm / 2) / row.length_mm;
        for (bool left : {true, false}) {
          if (options.omit && options.omit->row == static_cast<int>(r) &&
              options.omit->section == k && options.omit->stroke == j && options.omit->left == left)
            continue;
          const auto& s = strokes[static_cast<std::size_t>(j)];
          const double w = g.width(left ? s.left : s.right);
          if (w <= 0) continue;
          if (options.window && !d.reaches(f0, f1, row.offset_mm, *options.window)) continue;
          if (left)
            d.band(f0, f1, row.offset_mm - inner - w, row.offset_mm - inner);
          else
            d.band(f0, f1, row.offset_mm + inner, row.offset_mm + inner + w);
        }
      }
    }
  }
  cairo_fill(cr);
  if (options.label) drawLabel(cr, piece, sheet, half);
  cairo_restore(cr);
}

}  // namespace pitwall::print
