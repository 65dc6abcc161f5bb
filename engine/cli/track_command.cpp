// pitwall track show LAYOUT|FILE [--svg OUT]: a layout as the race view draws it (docs/view.md),
// to preview a track file before racing on it.
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>

#include "engine/cli/commands.hpp"
#include "engine/sim/track.hpp"
#include "engine/view/geometry.hpp"

namespace pitwall::cli {

int trackShow(const TrackShowOptions& options) {
  auto track = sim::loadLayout(options.layout);
  if (!track) {
    std::cerr << "pitwall track show: " << track.error() << "\n";
    return 2;
  }
  // With the drawing on stdout, the summary goes to stderr: stdout stays one SVG document.
  (options.svg == "-" ? std::cerr : std::cout) << view::trackSummary(*track);
  if (options.svg.empty()) return 0;
  const std::string svg = view::trackSvg(*track);
  if (options.svg == "-") {
    std::cout << svg;
    return std::cout.flush() ? 0 : 2;
  }
  std::ofstream out(options.svg, std::ios::binary | std::ios::trunc);
  if (out) out << svg;
  if (out) out.close();
  if (!out) {
    std::cerr << "pitwall track show: cannot write " << options.svg << ": " << std::strerror(errno)
              << "\n";
    return 2;
  }
  std::cerr << "wrote " << options.svg << "\n";
  return 0;
}

}  // namespace pitwall::cli
