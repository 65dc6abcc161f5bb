#include "engine/print/commands.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string_view>

#include "engine/core/printable.hpp"
#include "engine/print/code_options.hpp"
#include "engine/print/print.hpp"
#include "engine/print/raster.hpp"
#include "engine/print/sensor.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::print {

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

int printPieces(const PrintRequest& options) {
  const bool pdf = endsWith(options.out, ".pdf"), svg = endsWith(options.out, ".svg");
  if (!pdf && !svg) {
    std::cerr << "pitwall track print: --out '" << printable(options.out, 80)
              << "' names neither a .pdf nor a .svg file: end it in .pdf (tiled pages) or .svg "
                 "(one whole piece)\n";
    return 2;
  }
  auto paper = paperNamed(options.paper, options.landscape);
  if (!paper) {
    std::cerr << "pitwall track print: --paper: " << paper.error() << "\n";
    return 2;
  }
  auto code = withOverrides({}, options.code);
  if (!code) {
    std::cerr << "pitwall track print: " << code.error() << "\n";
    return 2;
  }
  auto pieces = piecesOf(options.what);
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
    auto pages = writePdf(options.out, *pieces, *paper, *code);
    if (!pages) {
      std::cerr << "pitwall track print: " << pages.error() << "\n";
      return 2;
    }
    std::cerr << "wrote " << options.out << ": " << pieces->size()
              << (pieces->size() == 1 ? " piece" : " pieces") << " on " << *pages << " "
              << paper->name << (options.landscape ? " landscape" : "") << " pages; print at "
              << "100 % (actual size) and check the 100 mm ruler\n";
    if (const std::string changed = codeDifferences(*code); !changed.empty())
      std::cerr << "code: " << changed << "\n";
    return 0;
  }
  // SVG: one whole piece per file; several pieces make OUT-1.svg, OUT-2.svg, … in order.
  const std::string stem = options.out.substr(0, options.out.size() - 4);
  for (std::size_t i = 0; i < pieces->size(); ++i) {
    auto text = pieceSvg((*pieces)[i], *code);
    if (!text) {
      std::cerr << "pitwall track print: " << text.error() << "\n";
      return 2;
    }
    const std::string path =
        pieces->size() == 1 ? options.out : stem + "-" + std::to_string(i + 1) + ".svg";
    if (!writeFile(path, *text)) return 2;
    std::cerr << "wrote " << path << ": " << pieceName((*pieces)[i]) << " (piece "
              << int((*pieces)[i].id) << ")\n";
  }
  return 0;
}

int verifyPiece(const VerifyRequest& options) {
  // CLI11's ranges let NaN through (no comparison with it is true).
  for (auto [name, value] : {std::pair{"--dpi", options.dpi}, std::pair{"--blur", options.blur_mm},
                             std::pair{"--misalign", options.misalign_mm}})
    if (!std::isfinite(value)) {
      std::cerr << "pitwall track verify: " << name << " " << value
                << " is not a number; give one in the range `pitwall track verify --help` shows\n";
      return 2;
    }
  auto loaded =
      loadPieceSvg(options.file, options.dpi, DrawLimits{options.draw_mb, options.draw_seconds});
  if (!loaded) {
    std::cerr << "pitwall track verify: " << loaded.error() << "\n";
    return 2;
  }
  auto& [raster, meta] = *loaded;
  auto code = withOverrides(meta.code, options.code);
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
  SensorModel model;
  model.blur_mm = options.blur_mm;
  model.misalign_mm = options.misalign_mm;
  std::cerr << "reading " << options.file << " at " << options.dpi << " dpi: " << pieceName(*piece)
            << " (piece " << int(piece->id) << "), blur " << model.blur_mm
            << " mm, misalignment up to " << model.misalign_mm << " mm";
  if (const std::string changed = codeDifferences(*code); !changed.empty())
    std::cerr << ", code " << changed;
  std::cerr << "\n";
  const auto result = readBack(raster, *piece, *code, model);
  std::cout << report(result, *piece, options.file, options.verbose);
  return result.ok() ? 0 : 1;
}

}  // namespace pitwall::print

extern "C" {
__attribute__((visibility("default"))) unsigned long pitwall_print_abi() {
  return pitwall::print::kRequestAbi;
}
__attribute__((visibility("default"))) int pitwall_print_pieces(
    const pitwall::print::PrintRequest* request) {
  return pitwall::print::printPieces(*request);
}
__attribute__((visibility("default"))) int pitwall_verify_piece(
    const pitwall::print::VerifyRequest* request) {
  return pitwall::print::verifyPiece(*request);
}
__attribute__((visibility("default"))) int pitwall_svg_png(
    const pitwall::print::PngRequest* request) {
  return pitwall::print::svgToPng(*request);
}
}
