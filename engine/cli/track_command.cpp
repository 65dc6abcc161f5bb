// pitwall track show LAYOUT|FILE [--svg OUT]: a layout as the race view draws it (docs/view.md),
// to preview a track file before racing on it. pitwall track list: the named layouts and Anki's
// stock pieces. pitwall track print PIECE|FILE --out OUT: its pieces to print at 1:1
// (engine/print); pitwall track verify FILE.svg: a printed piece read back as a car's sensor
// would (docs/cli.md).
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>

#include "engine/cli/commands.hpp"
#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/print_module.hpp"
#include "engine/sim/track.hpp"
#include "engine/view/geometry.hpp"

namespace pitwall::cli {

namespace {

// The drawing as a file of its own, to open in a browser or place in a page: it fills the window
// (or the box) it is shown in, whole, scaled as its viewBox — the drawing's bounds in mm — says.
// view::trackSvg's own width and height are a quarter of the track's size in mm (1992 mm of oval
// declared 498 mm), larger than a browser's window, which then shows one corner.
std::string scaledToFit(std::string svg) {
  for (const std::string attribute : {" width=\"", " height=\""}) {
    const auto rootEnd = svg.find('>');
    const auto at = svg.find(attribute);
    if (at == std::string::npos || at > rootEnd) continue;
    const auto close = svg.find('"', at + attribute.size());
    if (close == std::string::npos || close > rootEnd) continue;
    svg.replace(at, close + 1 - at, attribute + "100%\"");
  }
  return svg;
}

}  // namespace

int trackShow(const TrackShowOptions& options) {
  auto track = sim::loadLayout(options.layout);
  if (!track) {
    return fail("track show", track.error());
  }
  // With the drawing on stdout, the summary goes to stderr: stdout stays one SVG document.
  (options.svg == "-" ? std::cerr : std::cout) << view::trackSummary(*track);
  if (options.svg.empty()) return 0;
  const std::string svg = scaledToFit(view::trackSvg(*track));
  if (options.svg == "-") {
    std::cout << svg;
    return std::cout.flush() ? 0 : 2;
  }
  std::ofstream out(options.svg, std::ios::binary | std::ios::trunc);
  if (out) out << svg;
  if (out) out.close();
  if (!out) {
    return fail("track show", "cannot write " + options.svg + ": " + std::strerror(errno));
  }
  std::cerr << "wrote " << options.svg << "\n";
  return 0;
}

int trackList() {
  std::cout << "Layouts (a name works wherever a layout file does: --track, track show, track "
               "print):\n";
  char line[256];
  for (const std::string& name : sim::layoutNames()) {
    auto track = sim::namedLayout(name);
    if (!track) continue;  // every named layout parses (tests/unit/sim/track_test.cpp)
    const auto bounds = view::trackJson(*track, name)["bounds"];
    std::snprintf(line, sizeof line,
                  "  %-7s %2zu pieces, lap %.2f m, floor %.2f m × %.2f m: ", name.c_str(),
                  track->size(), track->lapLength(0) / 1000,
                  (bounds["maxX"].get<double>() - bounds["minX"].get<double>()) / 1000,
                  (bounds["maxY"].get<double>() - bounds["minY"].get<double>()) / 1000);
    std::cout << line << sim::layoutText(*track) << "\n";
  }
  std::cout << "Anki's stock pieces (track print ID prints one; a layout writes S:ID, L:ID or "
               "R:ID, and start for 34 and 33):\n";
  for (const sim::Piece& p : sim::stockPieces()) {
    const std::string type(anki::pieceTypeName(p.type));
    if (p.turn)
      std::snprintf(line, sizeof line, "  %-3d %-12s %g°, centre radius %g mm\n", p.id,
                    type.c_str(), p.angle(), p.radius());
    else
      std::snprintf(line, sizeof line, "  %-3d %-12s %g mm%s\n", p.id, type.c_str(), p.length(0),
                    p.type == anki::PieceType::StartLong    ? ", up to the finish line"
                    : p.type == anki::PieceType::StartShort ? ", from the finish line"
                                                            : "");
    std::cout << line;
  }
  // The pieces Anki made that pitwall has no shape for: named, so that their ids are known.
  for (int id = 0; id < 256; ++id) {
    const auto type = anki::pieceType(static_cast<std::uint8_t>(id));
    if (type == anki::PieceType::Unknown || sim::stockPiece(id)) continue;
    std::snprintf(line, sizeof line, "  %-3d %-12s no shape in pitwall: not in layouts or prints\n",
                  id, std::string(anki::pieceTypeName(type)).c_str());
    std::cout << line;
  }
  return std::cout.flush() ? 0 : 2;
}

int trackPrint(const TrackPrintOptions& options) {
  return runPrintModule("track print", options);
}

int trackVerify(const TrackVerifyOptions& options) {
  return runPrintModule("track verify", options);
}

Command addTrackCommand(CLI::App& app) {
  auto show = std::make_shared<TrackShowOptions>();
  auto printing = std::make_shared<TrackPrintOptions>();
  auto verify = std::make_shared<TrackVerifyOptions>();
  auto* track =
      app.add_subcommand("track", "Track layouts: show and list them, print and verify pieces");
  track->require_subcommand(1);
  auto* showCmd = track->add_subcommand(
      "show", "Describe a layout and draw it as the race view does: pitwall track show oval");
  showCmd->add_option("layout", show->layout, "A layout name (oval, kidney, long) or a layout file")
      ->required();
  showCmd->add_option("--svg", show->svg, "Write the drawing as SVG to OUT (- : stdout)");

  auto* listCmd = track->add_subcommand(
      "list", "The named layouts and Anki's stock pieces, with their ids: pitwall track list");

  auto* printCmd = track->add_subcommand(
      "print",
      "Pieces to print at 1:1 with their code: pitwall track print S:60,len=300 --out p.pdf");
  printCmd
      ->add_option("piece", printing->what,
                   "A piece (S, L:17, start, S:60,len=300, L:61,r=400,deg=45), a stock piece's "
                   "id (40; pitwall track list), a layout name or a layout file")
      ->required();
  printCmd
      ->add_option("--out,-o", printing->out,
                   "OUT.pdf: tiled pages of every piece; OUT.svg: one whole piece per file "
                   "(OUT-1.svg, OUT-2.svg, … for several)")
      ->required();
  printCmd->add_option("--paper", printing->paper, "Paper for the PDF: a4 (default) or a3");
  printCmd->add_flag("--landscape", printing->landscape, "Pages in landscape");
  printCmd->add_flag("--custom", printing->custom,
                     "Only the custom pieces (ids of their own), not Anki's stock ones");
  printCmd
      ->add_option("--code", printing->code,
                   "A stroke dimension in mm, NAME=VALUE, repeatable (the last wins): "
                   "stroke_pitch, stroke_length, line_width, gap, thin, thick, wide "
                   "(docs/cli.md)")
      ->allow_extra_args(false)
      ->type_name("NAME=MM");

  auto* verifyCmd = track->add_subcommand(
      "verify",
      "Read a printed piece's SVG back as a car's sensor would: pitwall track verify p.svg");
  verifyCmd->add_option("file", verify->file, "A piece SVG written by pitwall track print")
      ->required();
  verifyCmd->add_option("--dpi", verify->dpi, "The printer's resolution (default 300)")
      ->check(CLI::Range(50.0, 1200.0));
  verifyCmd->add_option("--blur", verify->blur_mm, "The sensor's blur, σ in mm (default 0.25)")
      ->check(CLI::Range(0.0, 1.0));
  verifyCmd
      ->add_option("--misalign", verify->misalign_mm,
                   "How far the sensor weaves beside the line, mm (default 0.5)")
      ->check(CLI::Range(0.0, 2.0));
  verifyCmd
      ->add_option("--code", verify->code,
                   "Read with this stroke dimension instead of the file's, NAME=VALUE in mm, "
                   "repeatable (as track print --code)")
      ->allow_extra_args(false)
      ->type_name("NAME=MM");
  verifyCmd
      ->add_option("--draw-mb", verify->draw_mb,
                   "Memory librsvg may take to draw the file, MB (default 512); more is refused")
      ->check(CLI::Range(16, 65536));
  verifyCmd
      ->add_option("--draw-seconds", verify->draw_seconds,
                   "CPU seconds librsvg may take to draw the file (default 20; twice that in "
                   "wall-clock time); longer is refused")
      ->check(CLI::Range(1, 3600));

  verifyCmd->add_flag("--verbose,-v", verify->verbose,
                      "A line for every row and direction, not only for those that fail");

  return {track, [=] {
            if (listCmd->parsed()) return cli::trackList();
            if (printCmd->parsed()) return cli::trackPrint(*printing);
            if (verifyCmd->parsed()) return cli::trackVerify(*verify);
            return cli::trackShow(*show);
          }};
}

}  // namespace pitwall::cli
