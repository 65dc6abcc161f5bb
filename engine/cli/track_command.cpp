// pitwall track show LAYOUT|FILE [--svg OUT]: a layout as the race view draws it (docs/view.md),
// to preview a track file before racing on it. pitwall track print PIECE|FILE --out OUT: its
// pieces to print at 1:1 (engine/print); pitwall track verify FILE.svg: a printed piece read back
// as a car's sensor would (docs/cli.md).
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <string_view>

#include "engine/cli/commands.hpp"
#include "engine/cli/options.hpp"
#include "engine/core/printable.hpp"
#include "engine/print/code_options.hpp"
#include "engine/print/print.hpp"
#include "engine/print/raster.hpp"
#include "engine/print/sensor.hpp"
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

namespace {

bool endsWith(std::string_view s, std::string_view tail) {
  return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail;
}

bool writeFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (out) out << text;
  if (out) out.close();
  if (!out) {
    std::cerr << "pitwall track print: cannot write " << path << ": " << std::strerror(errno)
              << "\n";
    return false;
  }
  return true;
}

}  // namespace

int trackPrint(const TrackPrintOptions& options) {
  const bool pdf = endsWith(options.out, ".pdf"), svg = endsWith(options.out, ".svg");
  if (!pdf && !svg) {
    std::cerr << "pitwall track print: --out '" << printable(options.out, 80)
              << "' names neither a .pdf nor a .svg file: end it in .pdf (tiled pages) or .svg "
                 "(one whole piece)\n";
    return 2;
  }
  auto paper = print::paperNamed(options.paper, options.landscape);
  if (!paper) {
    std::cerr << "pitwall track print: --paper: " << paper.error() << "\n";
    return 2;
  }
  auto code = print::withOverrides({}, options.code);
  if (!code) {
    std::cerr << "pitwall track print: " << code.error() << "\n";
    return 2;
  }
  auto pieces = print::piecesOf(options.what);
  if (!pieces) {
    std::cerr << "pitwall track print: " << pieces.error() << "\n";
    return 2;
  }
  if (options.custom) {  // the pieces a starter kit does not have
    std::erase_if(*pieces, [](const sim::Piece& p) {
      return anki::pieceType(p.id) != anki::PieceType::Unknown;
    });
    if (pieces->empty()) {
      std::cerr << "pitwall track print: " << printable(options.what, 80)
                << " has no custom pieces (ids of their own); leave out --custom to print "
                   "Anki's pieces too\n";
      return 2;
    }
  }
  if (pdf) {
    auto pages = print::writePdf(options.out, *pieces, *paper, *code);
    if (!pages) {
      std::cerr << "pitwall track print: " << pages.error() << "\n";
      return 2;
    }
    std::cerr << "wrote " << options.out << ": " << pieces->size()
              << (pieces->size() == 1 ? " piece" : " pieces") << " on " << *pages << " "
              << paper->name << (options.landscape ? " landscape" : "") << " pages; print at "
              << "100 % (actual size) and check the 100 mm ruler\n";
    if (const std::string changed = print::codeDifferences(*code); !changed.empty())
      std::cerr << "code: " << changed << "\n";
    return 0;
  }
  // SVG: one whole piece per file; several pieces make OUT-1.svg, OUT-2.svg, … in order.
  const std::string stem = options.out.substr(0, options.out.size() - 4);
  for (std::size_t i = 0; i < pieces->size(); ++i) {
    auto text = print::pieceSvg((*pieces)[i], *code);
    if (!text) {
      std::cerr << "pitwall track print: " << text.error() << "\n";
      return 2;
    }
    const std::string path =
        pieces->size() == 1 ? options.out : stem + "-" + std::to_string(i + 1) + ".svg";
    if (!writeFile(path, *text)) return 2;
    std::cerr << "wrote " << path << ": " << print::pieceName((*pieces)[i]) << " (piece "
              << int((*pieces)[i].id) << ")\n";
  }
  return 0;
}

int trackVerify(const TrackVerifyOptions& options) {
  // CLI11's ranges let NaN through (no comparison with it is true).
  for (auto [name, value] : {std::pair{"--dpi", options.dpi}, std::pair{"--blur", options.blur_mm},
                             std::pair{"--misalign", options.misalign_mm}})
    if (!std::isfinite(value)) {
      std::cerr << "pitwall track verify: " << name << " " << value
                << " is not a number; give one in the range `pitwall track verify --help` shows\n";
      return 2;
    }
  auto loaded = print::loadPieceSvg(options.file, options.dpi);
  if (!loaded) {
    std::cerr << "pitwall track verify: " << loaded.error() << "\n";
    return 2;
  }
  auto& [raster, meta] = *loaded;
  auto code = print::withOverrides(meta.code, options.code);
  if (!code) {
    std::cerr << "pitwall track verify: " << code.error() << "\n";
    return 2;
  }
  // The piece the metadata names: its token, and which of the token's pieces ("start" is two).
  auto pieces = sim::parsePiece(meta.token);
  const sim::Piece* piece = nullptr;
  if (pieces)
    for (const auto& p : *pieces)
      if (p.id == meta.piece_id) piece = &p;
  if (!piece) {
    std::cerr << "pitwall track verify: " << options.file << " names the piece '"
              << printable(meta.token, 80) << "' with id " << meta.piece_id << ", which "
              << (pieces ? std::string("is not among its pieces")
                         : "is not a piece: " + pieces.error())
              << "; print the piece again with `pitwall track print`\n";
    return 2;
  }
  print::SensorModel model;
  model.blur_mm = options.blur_mm;
  model.misalign_mm = options.misalign_mm;
  std::cerr << "reading " << options.file << " at " << options.dpi
            << " dpi: " << print::pieceName(*piece) << " (piece " << int(piece->id) << "), blur "
            << model.blur_mm << " mm, misalignment up to " << model.misalign_mm << " mm";
  if (const std::string changed = print::codeDifferences(*code); !changed.empty())
    std::cerr << ", code " << changed;
  std::cerr << "\n";
  const auto result = print::readBack(raster, *piece, *code, model);
  std::cout << print::report(result, *piece, options.file);
  return result.ok() ? 0 : 1;
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

  return {track, [=] {
            if (printCmd->parsed()) return cli::trackPrint(*printing);
            if (verifyCmd->parsed()) return cli::trackVerify(*verify);
            return cli::trackShow(*show);
          }};
}

}  // namespace pitwall::cli
