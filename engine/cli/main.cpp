// pitwall — the command line (docs/cli.md). Each command registers its own options in its own
// file (engine/cli/options.hpp); main lists them, parses, sets the log level and runs the one
// that was given.
#include <CLI/CLI.hpp>
#include <iostream>
#include <vector>

#include "engine/cli/options.hpp"
#include "engine/core/log.hpp"

int main(int argc, char** argv) {
  using namespace pitwall;
  CLI::App app{"pitwall — an automation engine for robot race cars, scripted in Lua"};
  app.require_subcommand(1);
  std::string logLevel;
  app.add_option("--log-level", logLevel,
                 "debug, info, warn, error or off (default: info; "
                 "warn for `test`)");

  const std::vector<cli::Command> commands = {
      cli::addRunCommand(app),      cli::addReplCommand(app),   cli::addBridgeCommand(app),
      cli::addViewCommand(app),     cli::addScanCommand(app),   cli::addEmulateCommand(app),
      cli::addSimRobotCommand(app), cli::addTestCommand(app),   cli::addReplayCommand(app),
      cli::addTrackCommand(app),    cli::addDecodeCommand(app), cli::addEncodeCommand(app),
      cli::addTypesCommand(app)};

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help prints and exits 0; every usage error is status 2 (docs/cli.md), not CLI11's own.
    return app.exit(e) == 0 ? 0 : 2;
  }
  cli::takeViews();

  for (const auto& command : commands) {
    if (!command.app->parsed()) continue;
    if (!logLevel.empty()) {
      auto level = log::parseLevel(logLevel);
      if (!level) {
        std::cerr << "pitwall: --log-level '" << logLevel
                  << "' is unknown; use debug, info, warn, error or off\n";
        return 2;
      }
      log::setLevel(*level);
    } else if (command.quiet) {
      log::setLevel(log::Level::Warn);
    }
    return command.run();
  }
  return 2;
}
