// pitwall track show LAYOUT|FILE [--svg OUT]: a layout as the race view draws it (docs/view.md),
// to preview a track file before racing on it.
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>

#include "engine/cli/commands.hpp"
#include "engine/cli/options.hpp"
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

Command addTrackCommand(CLI::App& app) {
  auto show = std::make_shared<TrackShowOptions>();
  auto* track = app.add_subcommand("track", "Track layouts");
  track->require_subcommand(1);
  auto* cmd = track->add_subcommand(
      "show", "Describe a layout and draw it as the race view does: pitwall track show oval");
  cmd->add_option("layout", show->layout, "A layout name (oval, kidney, long) or a layout file")
      ->required();
  cmd->add_option("--svg", show->svg, "Write the drawing as SVG to OUT (- : stdout)");
  return {cmd, [show] { return cli::trackShow(*show); }};
}

}  // namespace pitwall::cli
