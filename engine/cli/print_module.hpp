#pragma once
// The print module (pitwall_print.so: engine/print with cairo and librsvg), loaded only when
// `track print`, `track verify` or `compare --out FILE.png` runs, so that every other run stays
// without the ≈10 MB those libraries take once loaded (docs/performance.md). Found from where the
// binary is, as the data folder is (engine/core/data_dir.hpp): <exe>/../lib/pitwall/ when
// installed, <exe>/lib/pitwall/ in the build tree, or $PITWALL_PRINT_MODULE.
#include <string>

#include "engine/print/commands.hpp"

namespace pitwall::cli {

// Runs `track print` / `track verify` in the module (`command`: "track print", …): its exit status,
// or 2 with a sentence on stderr when the module cannot be loaded.
int runPrintModule(const char* command, const print::PrintRequest& request);
int runPrintModule(const char* command, const print::VerifyRequest& request);
// `compare --out FILE.png`: the charts' SVG drawn as a PNG ("compare" names the command).
int runPrintModule(const char* command, const print::PngRequest& request);

}  // namespace pitwall::cli
