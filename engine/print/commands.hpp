#pragma once
// `pitwall track print`, `pitwall track verify` and `compare --out FILE.png` as the print module
// runs them (docs/cli.md):
// what the command line asks, and the runs, which write to stdout/stderr and return the exit
// status. The module (pitwall_print.so) holds cairo and librsvg, which cost about 10 MB of memory
// once loaded; the command line loads it only for these two commands (engine/cli/print_module.cpp),
// calling the C entry points below.
#include <string>
#include <vector>

namespace pitwall::print {

// pitwall track print PIECE|FILE --out OUT.pdf|OUT.svg [--paper a4|a3] [--landscape] [--custom]
// [--code NAME=VALUE]…: printable pieces at 1:1.
struct PrintRequest {
  std::string what;  // a piece token, a layout file or a layout name
  std::string out;
  std::string paper = "a4";
  bool landscape = false;
  bool custom = false;            // only the pieces with an id of their own (not Anki's stock ones)
  std::vector<std::string> code;  // --code NAME=VALUE: stroke dimensions (code_options.hpp)
};
int printPieces(const PrintRequest& request);

// pitwall track verify FILE.svg [--dpi N] [--blur MM] [--misalign MM] [--code NAME=VALUE]…
// [--draw-mb N] [--draw-seconds N] [--verbose]:
// reads a printed piece back with the code dimensions its metadata gives (or --code's) as a
// car's sensor would; 0 all as designed, 1 not, 2 bad input.
struct VerifyRequest {
  std::string file;
  double dpi = 300;
  double blur_mm = 0.25;
  double misalign_mm = 0.5;
  std::vector<std::string> code;  // over the file's own dimensions
  int draw_mb = 512;              // what librsvg may spend drawing it (raster.hpp DrawLimits)
  int draw_seconds = 20;
  bool verbose = false;  // a line for every row and direction, not only for those that fail
};
int verifyPiece(const VerifyRequest& request);

// An SVG this program drew (`pitwall compare --out FILE.png`: docs/racing.md "Comparing laps")
// as a PNG at `scale` × its size, on white; 0 written, 1 (a sentence on stderr) not.
struct PngRequest {
  std::string command;  // for sentences: "compare"
  std::string svg;
  std::string out;
  double scale = 2;
};
int svgToPng(const PngRequest& request);

// The requests' layout, checked before a loaded module is used: a module from another build of
// pitwall, with other requests, is refused, never called. A version counted by hand (raise it
// when a field changes) and the structs' sizes.
inline constexpr unsigned long kRequestAbi = 3'000'000'000UL + sizeof(PrintRequest) * 1'000'000 +
                                             sizeof(VerifyRequest) * 1'000 + sizeof(PngRequest);

}  // namespace pitwall::print

// The module's entry points, looked up by name (dlsym); the same compiler builds both sides.
extern "C" {
unsigned long pitwall_print_abi();  // kRequestAbi of the build that made the module
int pitwall_print_pieces(const pitwall::print::PrintRequest* request);
int pitwall_verify_piece(const pitwall::print::VerifyRequest* request);
int pitwall_svg_png(const pitwall::print::PngRequest* request);
}
