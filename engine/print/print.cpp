#include "engine/print/print.hpp"

#include <cairo-pdf.h>
#include <cairo-svg.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <system_error>

#include "engine/print/code_options.hpp"
#include "engine/print/piece_drawing.hpp"
#include "engine/print/svg_metadata.hpp"

namespace pitwall::print {

namespace {

constexpr double kPointsPerMm = 72 / 25.4;
constexpr double kRulerMm = 100;

// Light cyan: plain to see, lighter than a reader's threshold (a mark on the road is no code).
void setMarkColour(cairo_t* cr) {
  cairo_set_source_rgb(cr, 0.2, 0.8, 1.0);
}

void cross(cairo_t* cr, double x, double y) {
  cairo_move_to(cr, x - 2, y);
  cairo_line_to(cr, x + 2, y);
  cairo_move_to(cr, x, y - 2);
  cairo_line_to(cr, x, y + 2);
  cairo_stroke(cr);
  cairo_arc(cr, x, y, 1.2, 0, 2 * std::numbers::pi);
  cairo_stroke(cr);
}

// A 100 mm ruler with 1, 5 and 10 mm ticks standing on `baseline`, from `x0`.
void ruler(cairo_t* cr, double x0, double baseline) {
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 0.15);
  cairo_move_to(cr, x0, baseline);
  cairo_line_to(cr, x0 + kRulerMm, baseline);
  for (int i = 0; i <= static_cast<int>(kRulerMm); ++i) {
    const double len = i % 10 == 0 ? 5 : i % 5 == 0 ? 3 : 2;
    cairo_move_to(cr, x0 + i, baseline);
    cairo_line_to(cr, x0 + i, baseline - len);
  }
  cairo_stroke(cr);
}

void text(cairo_t* cr, double x, double y, double size, const std::string& s) {
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, s.c_str());
}

// `s` at `size`, or smaller so that it fits `width` (mm).
void textWithin(cairo_t* cr, double x, double y, double size, double width, const std::string& s) {
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_text_extents_t e;
  cairo_text_extents(cr, s.c_str(), &e);
  if (e.x_advance > width) size *= width / e.x_advance;
  text(cr, x, y, size, s);
}

// One tile: the drawing's window at (column, row), then the marks and the band.
void page(cairo_t* cr, const sim::Piece& piece, const Sheet& sheet, const sim::CodeGeometry& g,
          const Paper& paper, const Tiling& t, int column, int row, const std::string& title) {
  const double m = paper.margin_mm, o = paper.overlap_mm;
  const double pw = paper.width_mm - 2 * m, ph = paper.height_mm - 2 * m - paper.band_mm;
  const double right = m + pw, bottom = m + ph;
  cairo_save(cr);
  cairo_rectangle(cr, m, m, pw, ph);
  cairo_clip(cr);
  const double x0 = column * t.step_x_mm, y0 = row * t.step_y_mm;
  cairo_translate(cr, m - x0, m - y0);
  DrawOptions options;
  options.window = Window{x0, y0, x0 + pw, y0 + ph};
  drawPiece(cr, piece, sheet, g, options);
  cairo_restore(cr);

  // Cut lines where this tile's edge is laid over its neighbour (left, top); dashed lines where
  // the strip the next tile repeats begins (right, bottom); crosses in each repeated strip, at
  // the same places of the drawing on both tiles, to align them.
  setMarkColour(cr);
  cairo_set_line_width(cr, 0.2);
  const double dash[] = {2, 1.5};
  if (column > 0) {
    cairo_move_to(cr, m, m);
    cairo_line_to(cr, m, bottom);
    cairo_stroke(cr);
  }
  if (row > 0) {
    cairo_move_to(cr, m, m);
    cairo_line_to(cr, right, m);
    cairo_stroke(cr);
  }
  cairo_set_dash(cr, dash, 2, 0);
  if (column + 1 < t.columns) {
    cairo_move_to(cr, right - o, m);
    cairo_line_to(cr, right - o, bottom);
    cairo_stroke(cr);
  }
  if (row + 1 < t.rows) {
    cairo_move_to(cr, m, bottom - o);
    cairo_line_to(cr, right, bottom - o);
    cairo_stroke(cr);
  }
  cairo_set_dash(cr, nullptr, 0, 0);
  const double along_y[] = {m + 12, m + ph / 2, bottom - 12};
  const double along_x[] = {m + 12, m + pw / 2, right - 12};
  for (double y : along_y) {
    if (column + 1 < t.columns) cross(cr, right - o / 2, y);
    if (column > 0) cross(cr, m + o / 2, y);
  }
  for (double x : along_x) {
    if (row + 1 < t.rows) cross(cr, x, bottom - o / 2);
    if (row > 0) cross(cr, x, m + o / 2);
  }

  // The band: what this page is, and the ruler that shows whether it was printed at 1:1.
  cairo_set_source_rgb(cr, 0, 0, 0);
  const double band = paper.height_mm - m - paper.band_mm;
  text(cr, m, band + 3.5, 2.8,
       title + ": tile " + std::to_string(row + 1) + "×" + std::to_string(column + 1) + " of " +
           std::to_string(t.rows) + "×" + std::to_string(t.columns) + " (row×column)");
  text(cr, m, band + 7, 2.8, "print at 100 % / actual size: the ruler must measure 100 mm");
  // A page drawn with calibrated strokes says so (code_options.hpp): which, and how wide.
  const std::string changed = codeDifferences(g);
  if (!changed.empty()) textWithin(cr, m, band + 10.5, 2.4, pw - kRulerMm - 3, "code: " + changed);
  ruler(cr, right - kRulerMm - 1, paper.height_mm - m - 0.5);
}

cairo_status_t appendTo(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

Result<Paper, std::string> paperNamed(std::string_view name, bool landscape) {
  Paper p;
  if (name == "a4" || name == "A4")
    p.name = "A4", p.width_mm = 210, p.height_mm = 297;
  else if (name == "a3" || name == "A3")
    p.name = "A3", p.width_mm = 297, p.height_mm = 420;
  else
    return Unexpected<std::string>("unknown paper '" + std::string(name) + "': use a4 or a3");
  if (landscape) std::swap(p.width_mm, p.height_mm);
  return p;
}

Tiling tiling(double width_mm, double height_mm, const Paper& paper) {
  Tiling t;
  const double pw = paper.width_mm - 2 * paper.margin_mm;
  const double ph = paper.height_mm - 2 * paper.margin_mm - paper.band_mm;
  t.step_x_mm = pw - paper.overlap_mm;
  t.step_y_mm = ph - paper.overlap_mm;
  // n tiles cover (n − 1)·step + the window; the last one reaches the sheet's far edge.
  t.columns = std::max(1, static_cast<int>(std::ceil((width_mm - pw) / t.step_x_mm - 1e-9)) + 1);
  t.rows = std::max(1, static_cast<int>(std::ceil((height_mm - ph) / t.step_y_mm - 1e-9)) + 1);
  return t;
}

namespace {

// What is printed: a right curve is its left curve's piece, laid the other way round.
std::vector<sim::Piece> printed(std::vector<sim::Piece> pieces) {
  for (sim::Piece& p : pieces) p = sim::printedPiece(p);
  return pieces;
}

}  // namespace

Result<std::vector<sim::Piece>, std::string> piecesOf(std::string_view arg) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(std::filesystem::path(arg), ec)) {
    auto track = sim::loadLayout(arg);
    if (!track) return Unexpected<std::string>(track.error());
    return printed(track->pieces());
  }
  // A number alone is a stock piece by its id, as `pitwall track list` lists them.
  if (!arg.empty() && arg.size() <= 9 &&
      std::all_of(arg.begin(), arg.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    auto stock = sim::stockPiece(std::stoi(std::string(arg)));
    if (!stock) return Unexpected<std::string>(stock.error());
    return printed({*stock});
  }
  auto piece = sim::parsePiece(arg);
  if (piece) return printed(*piece);
  if (auto named = sim::namedLayout(arg)) return printed(named->pieces());
  return Unexpected<std::string>(piece.error() + " (and no file is named '" + std::string(arg) +
                                 "')");
}

Result<int, std::string> writePdf(const std::string& path, const std::vector<sim::Piece>& pieces,
                                  const Paper& paper, const sim::CodeGeometry& g) {
  cairo_surface_t* surface = cairo_pdf_surface_create(path.c_str(), paper.width_mm * kPointsPerMm,
                                                      paper.height_mm * kPointsPerMm);
  cairo_t* cr = cairo_create(surface);
  int pages = 0;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const sim::Piece& piece = pieces[i];
    const Sheet sheet = sheetFor(piece, g);
    const Tiling t = tiling(sheet.width_mm, sheet.height_mm, paper);
    std::string title = pieceName(piece) + " (piece " + std::to_string(piece.id) + ")";
    if (pieces.size() > 1)
      title += ", " + std::to_string(i + 1) + " of " + std::to_string(pieces.size());
    for (int r = 0; r < t.rows; ++r)
      for (int c = 0; c < t.columns; ++c) {
        cairo_save(cr);
        cairo_scale(cr, kPointsPerMm, kPointsPerMm);
        page(cr, piece, sheet, g, paper, t, c, r, title);
        cairo_restore(cr);
        cairo_show_page(cr);
        ++pages;
      }
  }
  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t status = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  if (status != CAIRO_STATUS_SUCCESS)
    return Unexpected<std::string>("cannot write " + path + ": " + cairo_status_to_string(status));
  return pages;
}

Result<std::string, std::string> pieceSvg(const sim::Piece& piece, const sim::CodeGeometry& g) {
  const Sheet sheet = sheetFor(piece, g);
  std::string svg;
  // With millimetres as the document unit the surface's unit is the mm: width="…mm" and a
  // viewBox in mm, so the drawing's coordinates are the sheet's.
  cairo_surface_t* surface =
      cairo_svg_surface_create_for_stream(appendTo, &svg, sheet.width_mm, sheet.height_mm);
  cairo_svg_surface_set_document_unit(surface, CAIRO_SVG_UNIT_MM);
  cairo_t* cr = cairo_create(surface);
  drawPiece(cr, piece, sheet, g);
  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t status = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  if (status != CAIRO_STATUS_SUCCESS)
    return Unexpected<std::string>(std::string("cannot draw the SVG: ") +
                                   cairo_status_to_string(status));
  return withMetadata(svg, {pieceName(piece), piece.id, sheet, g});
}

}  // namespace pitwall::print
