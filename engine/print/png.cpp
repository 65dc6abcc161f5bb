// An SVG this program drew, as a PNG (print/commands.hpp svgToPng): `pitwall compare --out
// FILE.png`. The SVG is pitwall's own (core/svg_chart), so librsvg reads it here, in process;
// the hostile files of `track verify` are read in a child under limits (raster.cpp).
#include <cairo.h>
#include <librsvg/rsvg.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>

#include "engine/print/commands.hpp"

namespace pitwall::print {

namespace {
constexpr double kMaxSide = 20000;  // pixels: a chart is some hundred; this is no chart
}

int svgToPng(const PngRequest& request) {
  const std::string who = "pitwall " + request.command + ": ";
  GError* error = nullptr;
  RsvgHandle* handle = rsvg_handle_new_from_data(
      reinterpret_cast<const guint8*>(request.svg.data()), request.svg.size(), &error);
  if (!handle) {
    std::cerr << who << "the charts could not be read back to draw them as a PNG ("
              << (error ? error->message : "no reason given") << ")\n";
    if (error) g_error_free(error);
    return 1;
  }
  double w = 0, h = 0;
  const double scale = request.scale > 0 && request.scale <= 8 ? request.scale : 2;
  if (!rsvg_handle_get_intrinsic_size_in_pixels(handle, &w, &h) || !(w > 0 && h > 0) ||
      w * scale > kMaxSide || h * scale > kMaxSide) {
    std::cerr << who << "the charts have no size a PNG can have\n";
    g_object_unref(handle);
    return 1;
  }
  const int width = static_cast<int>(std::ceil(w * scale));
  const int height = static_cast<int>(std::ceil(h * scale));
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
  cairo_t* cr = cairo_create(surface);
  cairo_set_source_rgb(cr, 1, 1, 1);  // on white, as the SVG is shown on a page
  cairo_paint(cr);
  cairo_scale(cr, scale, scale);
  const RsvgRectangle viewport{0, 0, w, h};
  const bool drawn = rsvg_handle_render_document(handle, cr, &viewport, &error);
  cairo_destroy(cr);
  g_object_unref(handle);
  if (!drawn) {
    std::cerr << who << "the charts could not be drawn as a PNG ("
              << (error ? error->message : "no reason given") << ")\n";
    if (error) g_error_free(error);
    cairo_surface_destroy(surface);
    return 1;
  }
  // Written beside it and renamed over it: a write that fails leaves no half a picture
  const std::string part = request.out + ".part";
  const cairo_status_t written = cairo_surface_write_to_png(surface, part.c_str());
  cairo_surface_destroy(surface);
  std::error_code ec;
  if (written == CAIRO_STATUS_SUCCESS) std::filesystem::rename(part, request.out, ec);
  if (written != CAIRO_STATUS_SUCCESS || ec) {
    std::filesystem::remove(part, ec);
    std::cerr << who << "cannot write " << request.out << " ("
              << (written != CAIRO_STATUS_SUCCESS ? cairo_status_to_string(written)
                                                  : "it cannot take the picture's place")
              << "): give a file in a folder that exists and takes files\n";
    return 1;
  }
  return 0;
}

}  // namespace pitwall::print
