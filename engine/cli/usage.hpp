#pragma once
// The command line's front door (docs/cli.md): what bare `pitwall` prints, and the one-line
// answer to a mistyped command or option ("pitwall: unknown command 'rn'; did you mean run?").
#include <CLI/CLI.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace pitwall::cli {

// The commands with one line each, and where to go next.
void printCommands(const CLI::App& app, std::ostream& out);

// After CLI11 refused argv: the first word it could not place — a command that does not exist,
// or an option the command does not have — as one sentence with the nearest name, and where to
// look. nullopt when the refusal is of another kind (a missing or bad value), which CLI11 says
// well enough.
std::optional<std::string> explainRefusal(const CLI::App& app, int argc, const char* const* argv);

// The long options of `cmd` and of its parents (whose options fall through to it): "--seed", …
std::vector<std::string> longOptions(const CLI::App& cmd);

}  // namespace pitwall::cli
