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
#include <string>

#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <iostream>
#include <new>

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

namespace {

// What the drawing process sends back over its pipe: 'R', width, height (int32) and the raster's
// darkness bytes row by row; or 'E', a length (uint32) and the sentence why not.
bool writeAll(int fd, const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

[[noreturn]] void childError(int fd, const std::string& why) {
  const char tag = 'E';
  const auto size = static_cast<std::uint32_t>(why.size());
  writeAll(fd, &tag, 1);
  writeAll(fd, &size, sizeof size);
  writeAll(fd, why.data(), why.size());
  ::_exit(0);
}

// The drawing process: parses the SVG with librsvg and renders it band by band into the pipe. It
// runs under the limits set before it starts; whatever librsvg does with a hostile file ends here.
[[noreturn]] void drawInChild(int fd, const std::string& svg, double dpi) {
  GError* error = nullptr;
  RsvgHandle* handle =
      rsvg_handle_new_from_data(reinterpret_cast<const guint8*>(svg.data()), svg.size(), &error);
  if (!handle) childError(fd, "is not an SVG librsvg can read (" + messageOf(error) + ")");
  rsvg_handle_set_dpi(handle, dpi);
  double w = 0, h = 0;
  if (!rsvg_handle_get_intrinsic_size_in_pixels(handle, &w, &h) || !(w > 0 && h > 0))
    childError(fd,
               "has no width and height in absolute units (mm): it cannot be printed at actual "
               "size");
  if (!std::isfinite(w) || !std::isfinite(h) || w > kMaxSide || h > kMaxSide ||
      w * h > kMaxPixels) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%.0f × %.0f mm at %g dpi is %.0f million pixels",
                  w / dpi * 25.4, h / dpi * 25.4, dpi, w * h / 1e6);
    childError(fd, std::string(": ") + buf + ", too many to read back; use a lower --dpi");
  }
  Raster band;
  band.width = static_cast<int>(std::ceil(w));
  const int height = static_cast<int>(std::ceil(h));
  const char tag = 'R';
  const std::int32_t size[2] = {band.width, height};
  if (!writeAll(fd, &tag, 1) || !writeAll(fd, size, sizeof size)) ::_exit(1);
  // Band by band, each rendered on its own: only one band's bytes are held here.
  for (int y0 = 0; y0 < height; y0 += kBandRows) {
    band.height = std::min(kBandRows, height - y0);
    bool rendered = true;
    std::string why;
    rasterize(band, [&](cairo_t* cr) {
      cairo_translate(cr, 0, -y0);
      const RsvgRectangle viewport{0, 0, w, h};
      GError* e = nullptr;
      if (!rsvg_handle_render_document(handle, cr, &viewport, &e)) {
        rendered = false;
        why = messageOf(e);
        if (e) g_error_free(e);
      }
    });
    if (band.dark.empty() || !rendered) ::_exit(rendered ? 3 : 4);
    if (!writeAll(fd, band.dark.data(), band.dark.size())) ::_exit(1);
  }
  ::_exit(0);
}

std::string signalName(int signal) {
  const char* abbrev = ::sigabbrev_np(signal);
  return abbrev ? std::string("SIG") + abbrev : "signal " + std::to_string(signal);
}

// Reads exactly `size` bytes before `deadline`; false on the end of the pipe or the deadline.
bool readAll(int fd, void* data, std::size_t size, std::chrono::steady_clock::time_point deadline,
             bool& late) {
  char* p = static_cast<char*>(data);
  while (size > 0) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return late = true, false;
    pollfd pfd{fd, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0) return false;
    if (ready == 0) continue;
    const ssize_t n = ::read(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

// The address space this process has mapped now (the child starts with all of it).
std::uint64_t mappedBytes() {
  std::ifstream statm("/proc/self/statm");
  std::uint64_t pages = 0;
  statm >> pages;
  return pages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
}

}  // namespace

Result<std::pair<Raster, PieceSvg>, std::string> loadPieceSvg(const std::string& path, double dpi,
                                                              const DrawLimits& limits) {
  using Error = Unexpected<std::string>;
  // The size first, then a read of at most one byte more than allowed (the file may grow).
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    return Error("cannot read " + path + ": " + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    return Error(path + " is not a file: give the SVG that `pitwall track print` wrote");
  auto tooLarge = [&](std::uint64_t bytes) {
    return Error(path + " is " + std::to_string(bytes) + " bytes, more than the " +
                 std::to_string(kMaxSvgBytes) +
                 " a piece SVG can be (`pitwall track print` writes well under 1 MB): print the "
                 "piece again with `pitwall track print`");
  };
  if (static_cast<std::uint64_t>(st.st_size) > kMaxSvgBytes) return tooLarge(st.st_size);
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error("cannot read " + path + ": " + std::strerror(errno));
  std::string svg(kMaxSvgBytes + 1, '\0');
  in.read(svg.data(), static_cast<std::streamsize>(svg.size()));
  svg.resize(static_cast<std::size_t>(in.gcount()));
  if (svg.size() > kMaxSvgBytes) return tooLarge(svg.size());
  auto meta = readMetadata(svg);
  if (!meta)
    return Error(path + " is not a piece SVG written by `pitwall track print` (" + meta.error() +
                 "): print the piece with `pitwall track print PIECE --out FILE.svg` and verify "
                 "that file");
  // Entities: a few lines of <!ENTITY> can expand to gigabytes, and librsvg expands internal
  // ones. A piece SVG declares none, so a file that does is refused before any parser sees it.
  if (svg.find("<!ENTITY") != std::string::npos)
    return Error(path +
                 " declares XML entities (<!ENTITY …> in its DOCTYPE), which a piece SVG never "
                 "does and which can expand a small file into gigabytes: it is not read; print "
                 "the piece again with `pitwall track print`");

  // librsvg parses and draws in a child process with its address space, CPU time and wall-clock
  // time bounded: a file that asks too much ends that process, not this one (docs/cli.md).
  std::cout.flush();
  std::cerr.flush();
  int pipeFd[2];
  if (::pipe2(pipeFd, O_CLOEXEC) != 0)
    return Error(std::string("cannot start the drawing of ") + path + ": " + std::strerror(errno));
  const std::uint64_t allowed = mappedBytes() + limits.megabytes * 1024ull * 1024ull;
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(pipeFd[0]);
    ::close(pipeFd[1]);
    return Error(std::string("cannot start the drawing of ") + path + ": " + std::strerror(errno));
  }
  if (child == 0) {
    ::close(pipeFd[0]);
    const rlimit none{0, 0};
    ::setrlimit(RLIMIT_CORE, &none);  // an abort leaves no core file behind
    const rlimit as{allowed, allowed};
    ::setrlimit(RLIMIT_AS, &as);
    const rlimit cpu{static_cast<rlim_t>(limits.seconds), static_cast<rlim_t>(limits.seconds) + 1};
    ::setrlimit(RLIMIT_CPU, &cpu);
    // what glib or Rust print as they give up is not this command's sentence
    if (int null = ::open("/dev/null", O_WRONLY); null >= 0) ::dup2(null, 2);
    drawInChild(pipeFd[1], svg, dpi);
  }
  ::close(pipeFd[1]);
  // Twice the CPU time in wall-clock time: a busy machine is slower, a stuck child is stopped.
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(2 * limits.seconds + 1);
  const int fd = pipeFd[0];
  bool late = false;
  Raster r;
  r.sheet = meta->sheet;
  r.px_per_mm = dpi / 25.4;
  std::string why;  // the child's own sentence
  bool whole = false;
  char tag = 0;
  if (readAll(fd, &tag, 1, deadline, late)) {
    if (tag == 'E') {
      std::uint32_t size = 0;
      if (readAll(fd, &size, sizeof size, deadline, late) && size <= 4096) {
        why.resize(size);
        if (!readAll(fd, why.data(), size, deadline, late)) why.clear();
      }
    } else if (tag == 'R') {
      std::int32_t size[2] = {0, 0};
      if (readAll(fd, size, sizeof size, deadline, late) && size[0] > 0 && size[1] > 0 &&
          static_cast<double>(size[0]) * size[1] <= kMaxPixels) {
        r.width = size[0];
        r.height = size[1];
        try {  // this process's own limit (ulimit -v) may not hold the raster
          r.dark.resize(static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height));
          whole = readAll(fd, r.dark.data(), r.dark.size(), deadline, late);
        } catch (const std::bad_alloc&) {
          why = "is " + std::to_string(r.width) + " × " + std::to_string(r.height) +
                " pixels at this --dpi, more than this process has memory for: use a lower "
                "--dpi";
        }
      }
    }
  }
  if (late) ::kill(child, SIGKILL);
  ::close(fd);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (!why.empty())
    return Error(path + (why.rfind(": ", 0) == 0 ? "" : " ") + why +
                 (why.find("--dpi") == std::string::npos
                      ? ": print the piece again with `pitwall track print`"
                      : ""));
  const int signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  if (late || signal == SIGXCPU || (signal == SIGKILL && !whole))
    return Error("the SVG took more than " + std::to_string(limits.seconds) +
                 " s to draw: " + path +
                 " is not read (a piece SVG draws in well under a second; a blur or filter "
                 "someone added can take minutes); print the piece again with `pitwall track "
                 "print`, or allow more with --draw-seconds");
  if (signal != 0)
    return Error("the SVG took more than " + std::to_string(limits.megabytes) +
                 " MB to draw: " + path + " is not read (librsvg ended with " + signalName(signal) +
                 ", as it does when memory runs out); print the piece again with `pitwall track "
                 "print`, or allow more with --draw-mb");
  if (!whole || WEXITSTATUS(status) != 0)
    return Error(path + " could not be rendered (" +
                 (WEXITSTATUS(status) == 3 ? std::string("no memory for a band of the raster")
                                           : std::string("librsvg could not draw it")) +
                 "): print the piece again with `pitwall track print`");
  return std::pair{std::move(r), std::move(*meta)};
}

}  // namespace pitwall::print
