#include "engine/print/raster.hpp"

#include <librsvg/rsvg.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>

namespace pitwall::print {

namespace {

// A raster too large to hold (a sheet metres wide, or a huge --dpi) is refused, not attempted.
constexpr double kMaxPixels = 300e6;
constexpr int kBandRows = 512;  // rendered a band at a time: one byte per pixel is kept
// cairo's image surfaces are at most this many pixels wide (or high).
constexpr double kMaxSide = 32767;

// A GError's message without the newline librsvg may end it with.
std::string messageOf(const GError* e) {
  std::string m = e ? e->message : "unknown error";
  while (!m.empty() && (m.back() == '\n' || m.back() == ' ')) m.pop_back();
  return m;
}

// Renders `paint` (user space: pixels) band by band on white, keeping darkness bytes.
void rasterize(Raster& r, const std::function<void(cairo_t*)>& paint) {
  r.dark.assign(static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height), 0);
  for (int y0 = 0; y0 < r.height; y0 += kBandRows) {
    const int rows = std::min(kBandRows, r.height - y0);
    cairo_surface_t* band = cairo_image_surface_create(CAIRO_FORMAT_RGB24, r.width, rows);
    if (cairo_surface_status(band) != CAIRO_STATUS_SUCCESS) {  // the callers keep within limits
      cairo_surface_destroy(band);
      r.dark.clear();
      r.width = r.height = 0;
      return;
    }
    cairo_t* cr = cairo_create(band);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_translate(cr, 0, -y0);
    paint(cr);
    cairo_destroy(cr);
    cairo_surface_flush(band);
    const unsigned char* data = cairo_image_surface_get_data(band);
    const int stride = cairo_image_surface_get_stride(band);
    for (int y = 0; y < rows; ++y) {
      const auto* px = reinterpret_cast<const std::uint32_t*>(data + y * stride);
      std::uint8_t* out = &r.dark[static_cast<std::size_t>(y0 + y) * r.width];
      for (int x = 0; x < r.width; ++x) {
        const std::uint32_t v = px[x];
        const int lum =
            (299 * ((v >> 16) & 0xff) + 587 * ((v >> 8) & 0xff) + 114 * (v & 0xff)) / 1000;
        out[x] = static_cast<std::uint8_t>(255 - lum);
      }
    }
    cairo_surface_destroy(band);
  }
}

}  // namespace

double Raster::darkness(double x_mm, double y_mm) const {
  const double fx = x_mm * px_per_mm - 0.5, fy = y_mm * px_per_mm - 0.5;
  if (!(fx > -1 && fy > -1 && fx < width && fy < height)) return 0;
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  const double tx = fx - x0, ty = fy - y0;
  auto at = [&](int x, int y) -> double {
    if (x < 0 || y < 0 || x >= width || y >= height) return 0;
    return dark[static_cast<std::size_t>(y) * width + x];
  };
  const double top = at(x0, y0) * (1 - tx) + at(x0 + 1, y0) * tx;
  const double bottom = at(x0, y0 + 1) * (1 - tx) + at(x0 + 1, y0 + 1) * tx;
  return (top * (1 - ty) + bottom * ty) / 255.0;
}

Raster renderPiece(const sim::Piece& piece, double px_per_mm, const sim::CodeGeometry& g,
                   const DrawOptions& options, double scale) {
  Raster r;
  r.sheet = sheetFor(piece, g);
  r.px_per_mm = px_per_mm;
  // The page grows with the drawing, as a scaled print does: nothing is cut off.
  r.width = static_cast<int>(std::ceil(r.sheet.width_mm * std::max(1.0, scale) * px_per_mm));
  r.height = static_cast<int>(std::ceil(r.sheet.height_mm * std::max(1.0, scale) * px_per_mm));
  rasterize(r, [&](cairo_t* cr) {
    cairo_scale(cr, px_per_mm * scale, px_per_mm * scale);
    drawPiece(cr, piece, r.sheet, g, options);
  });
  return r;
}

Result<std::pair<Raster, PieceSvg>, std::string> loadPieceSvg(const std::string& path, double dpi) {
  using Error = Unexpected<std::string>;
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error("cannot read " + path + ": " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  const std::string svg = text.str();
  auto meta = readMetadata(svg);
  if (!meta)
    return Error(path + " is not a piece SVG written by `pitwall track print` (" + meta.error() +
                 "): print the piece with `pitwall track print PIECE --out FILE.svg` and verify "
                 "that file");
  GError* error = nullptr;
  RsvgHandle* handle =
      rsvg_handle_new_from_data(reinterpret_cast<const guint8*>(svg.data()), svg.size(), &error);
  if (!handle) {
    std::string why = messageOf(error);
    if (error) g_error_free(error);
    return Error(path + " is not an SVG librsvg can read (" + why +
                 "): print the piece again with `pitwall track print`");
  }
  rsvg_handle_set_dpi(handle, dpi);
  double w = 0, h = 0;
  if (!rsvg_handle_get_intrinsic_size_in_pixels(handle, &w, &h) || !(w > 0 && h > 0)) {
    g_object_unref(handle);
    return Error(path +
                 " has no width and height in absolute units (mm): it cannot be printed "
                 "at actual size; print the piece again with `pitwall track print`");
  }
  if (!std::isfinite(w) || !std::isfinite(h) || w > kMaxSide || h > kMaxSide ||
      w * h > kMaxPixels) {
    g_object_unref(handle);
    char buf[160];
    std::snprintf(buf, sizeof buf, "%.0f × %.0f mm at %g dpi is %.0f million pixels",
                  w / dpi * 25.4, h / dpi * 25.4, dpi, w * h / 1e6);
    return Error(path + ": " + buf + ", too many to read back; use a lower --dpi");
  }
  Raster r;
  r.sheet = meta->sheet;
  r.px_per_mm = dpi / 25.4;
  r.width = static_cast<int>(std::ceil(w));
  r.height = static_cast<int>(std::ceil(h));
  bool rendered = true;
  std::string why;
  rasterize(r, [&](cairo_t* cr) {
    const RsvgRectangle viewport{0, 0, w, h};
    GError* e = nullptr;
    if (!rsvg_handle_render_document(handle, cr, &viewport, &e)) {
      rendered = false;
      why = messageOf(e);
      if (e) g_error_free(e);
    }
  });
  g_object_unref(handle);
  if (!rendered)
    return Error(path + " could not be rendered (" + why +
                 "): print the piece again with `pitwall track print`");
  return std::pair{std::move(r), std::move(*meta)};
}

}  // namespace pitwall::print
