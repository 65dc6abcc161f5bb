// pitwall track show LAYOUT|FILE [--svg OUT]: a layout as the race view draws it (docs/view.md),
// to preview a track file before racing on it. pitwall track print PIECE|FILE --out OUT: its
// pieces to print at 1:1 (engine/print); pitwall track verify FILE.svg: a printed piece read back
// as a car's sensor would (docs/cli.md).
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>

#include "engine/cli/commands.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/print_module.hpp"
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

int trackPrint(const TrackPrintOptions& options) {
  return runPrintModule("print", options);
}

int trackVerify(const TrackVerifyOptions& options) {
  return runPrintModule("verify", options);
}

Command addTrackCommand(CLI::App& app) {
  auto show = std::make_shared<TrackShowOptions>();
  auto printing = std::make_shared<TrackPrintOptions>();
  auto verify = std::make_shared<TrackVerifyOptions>();
  auto* track = app.add_subcommand("track", "Track layouts: show, print and verify pieces");
  track->require_subcommand(1);
  auto* showCmd = track->add_subcommand(
      "show", "Describe a layout and draw it as the race view does: pitwall track show oval");
  showCmd->add_option("layout", show->layout, "A layout name (oval, kidney, long) or a layout file")
      ->required();
  showCmd->add_option("--svg", show->svg, "Write the drawing as SVG to OUT (- : stdout)");

  auto* printCmd = track->add_subcommand(
      "print",
      "Pieces to print at 1:1 with their code: pitwall track print S:60,len=300 --out p.pdf");
  printCmd
      ->add_option("piece", printing->what,
                   "A piece (S, L:17, start, S:60,len=300, L:61,r=400,deg=45) or a layout file")
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

  return {track, [=] {
            if (printCmd->parsed()) return cli::trackPrint(*printing);
            if (verifyCmd->parsed()) return cli::trackVerify(*verify);
            return cli::trackShow(*show);
          }};
}

}  // namespace pitwall::cli
