#pragma once
// `pitwall --version` (docs/cli.md): the first line is "pitwall VERSION[ (git DESCRIBE)]", as
// help2man and scripts read it; then the libraries it was built with and runs on, and where its
// data is.
#include <string>

namespace pitwall::cli {
std::string versionText();
}
