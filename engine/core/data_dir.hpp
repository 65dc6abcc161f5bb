#pragma once
// Where pitwall's data is — the Lua library (scripts/), the examples, the race view's page (web/)
// and the editor definitions (types/) — found from where the binary is, never from a path
// compiled in: an installed or unpacked tree (bin/pitwall beside share/pitwall/), the build tree
// (build/pitwall beside build/share/pitwall/, whose scripts/, examples/ and types/ link to the
// source), or $PITWALL_DATA. docs/install.md.
#include <filesystem>
#include <string>
#include <vector>

#include "engine/core/result.hpp"

namespace pitwall {

// The folder of the running executable (/proc/self/exe); empty when it cannot be read.
std::filesystem::path executableDir();

// The places looked at, in order: $PITWALL_DATA when set, then <exe>/../share/pitwall and
// <exe>/share/pitwall.
std::vector<std::filesystem::path> dataDirCandidates();

// The first candidate that holds scripts/pitwall/core.lua (made absolute); a $PITWALL_DATA that
// does not is an error of its own. The error names the places looked at and what to do.
Result<std::filesystem::path, std::string> dataDir();

}  // namespace pitwall
