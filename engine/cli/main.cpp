// pitwall — the command line (docs/cli.md). Each command registers its own options in its own
// file (engine/cli/options.hpp); main lists them, parses, sets the log level and runs the one
// that was given. Bare `pitwall` lists the commands; a mistyped one gets the nearest
// (engine/cli/usage.hpp).
#include <CLI/CLI.hpp>
#include <iostream>
#include <optional>
#include <string_view>
#include <vector>

#include "engine/cli/options.hpp"
#include "engine/cli/usage.hpp"
#include "engine/cli/version.hpp"
#include "engine/core/log.hpp"
#include "engine/core/printable.hpp"

int main(int argc, char** argv) {
  using namespace pitwall;
  CLI::App app{"pitwall — an automation engine for robot race cars, scripted in Lua", "pitwall"};
  app.require_subcommand(0, 1);
  // The options below work after the command too (`pitwall run x.lua -q`): every command made
  // after this inherits it and passes what it does not know up to here.
  app.fallthrough();
  std::string logLevel;
  bool quiet = false, version = false;
  app.add_option("--log-level", logLevel,
                 "debug, info, warn, error or off (default: info; "
                 "warn for `test`)");
  app.add_flag("-q,--quiet", quiet, "Only warnings and errors (--log-level warn)");
  app.add_flag("--version", version, "The version, the libraries, where the data is");

  const std::vector<cli::Command> commands = {
      cli::addRunCommand(app),      cli::addReplCommand(app),      cli::addBridgeCommand(app),
      cli::addViewCommand(app),     cli::addScanCommand(app),      cli::addEmulateCommand(app),
      cli::addSimRobotCommand(app), cli::addTestCommand(app),      cli::addLeagueCommand(app),
      cli::addTryCommand(app),      cli::addStandingsCommand(app), cli::addReplayCommand(app),
      cli::addCompareCommand(app),  cli::addTrackCommand(app),     cli::addDecodeCommand(app),
      cli::addEncodeCommand(app),   cli::addTypesCommand(app),     cli::addCompletionCommand(app)};

  // --version anywhere on the line answers before anything else is checked
  // (`pitwall run --version` has no script to ask for).
  for (int i = 1; i < argc && std::string_view(argv[i]) != "--"; ++i)
    if (std::string_view(argv[i]) == "--version") {
      std::cout << cli::versionText() << "\n";
      return 0;
    }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0) {
      if (auto why = cli::explainRefusal(app, argc, argv)) {
        std::cerr << *why << "\n";
        return 2;
      }
    }
    // --help prints and exits 0; every usage error is status 2 (docs/cli.md), not CLI11's own.
    return app.exit(e) == 0 ? 0 : 2;
  }
  (void)version;  // answered above
  cli::takeViews();
  std::optional<log::Level> level;
  if (!logLevel.empty() && !(level = log::parseLevel(logLevel))) {
    std::cerr << "pitwall: --log-level '" << printable(logLevel, 80)
              << "' is unknown; use debug, info, warn, error or off\n";
    return 2;
  }

  for (const auto& command : commands) {
    if (!command.app->parsed()) continue;
    if (level) {
      log::setLevel(*level);
    } else if (quiet || command.quiet) {
      log::setLevel(log::Level::Warn);
    }
    return command.run();
  }
  cli::printCommands(app, std::cout);
  return 0;
}
