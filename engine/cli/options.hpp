#pragma once
// How a subcommand joins the command line (docs/cli.md): each command's file registers its own
// options on the app and says what runs it (`Command`); main only lists the commands. The options
// several commands share — where the cars come from, the broker, the view — are made here.
#include <CLI/CLI.hpp>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "engine/cli/commands.hpp"

namespace pitwall::cli {

struct Command {
  CLI::App* app = nullptr;   // the subcommand; it ran when app->parsed()
  std::function<int()> run;  // the exit status
  bool quiet = false;        // the log level defaults to warn (`test`), not info
};

// One function per subcommand, in the file of the command it registers.
Command addRunCommand(CLI::App& app);
Command addReplCommand(CLI::App& app);
Command addBridgeCommand(CLI::App& app);
Command addViewCommand(CLI::App& app);
Command addScanCommand(CLI::App& app);
Command addEmulateCommand(CLI::App& app);
Command addSimRobotCommand(CLI::App& app);
Command addTestCommand(CLI::App& app);
Command addLeagueCommand(CLI::App& app);     // `league DIR|FILES…` (docs/league.md)
Command addTryCommand(CLI::App& app);        // `try FILE`: a driver alone in the simulator
Command addStandingsCommand(CLI::App& app);  // `standings` (docs/league.md "Standings")
Command addReplayCommand(CLI::App& app);
Command addCompareCommand(CLI::App& app);  // `compare A B …`: laps side by side (docs/racing.md)
Command addTrackCommand(CLI::App& app);  // `track show`, `list`, `print`, `verify`
Command addDecodeCommand(CLI::App& app);
Command addEncodeCommand(CLI::App& app);
Command addTypesCommand(CLI::App& app);       // `types [DIR]`: LuaLS definitions (docs/editor.md)
Command addCompletionCommand(CLI::App& app);  // `completion bash|zsh`

// --seed, --cars, --track, --ble and its companions, --budget, --lua-memory (run, repl, bridge);
// `when` ends the help of --scan-timeout. Returns the --ble flag.
CLI::Option* addCarSource(CLI::App* cmd, CarSource& source, const char* when);
// --firmware VERSION (hex): the version simulated cars answer, and so the layouts they send
// (docs/simulator.md "Firmware families"); `whose` names the cars in the help.
CLI::Option* addFirmware(CLI::App* cmd, std::uint16_t& firmware, const char* whose);
// --mqtt URL and how to log in; `what` says what the broker is for. Returns --mqtt.
CLI::Option* addMqtt(CLI::App* cmd, MqttSettings& mqtt, double& timeout, const char* what);
// --mqtt for run and repl: the cars bridged by other hosts, and --remote-cars.
CLI::Option* addRemoteCars(CLI::App* cmd, CarSource& source);
// --view [[HOST:]PORT], an option whose value may be left out: CLI11 tells whether it was given
// only after parsing, so takeViews() copies each one to its target then.
// With it, --view-host NAME (repeatable): the names of the given --view, from viewHosts().
CLI::Option* addView(CLI::App* cmd, std::optional<std::string>& target);
void takeViews();
const std::vector<std::string>& viewHosts();
// --humans N, --gamepads, --keyboard (run): the seats of human drivers and what holds them.
void addHumans(CLI::App* cmd, CarSource& source);
// --driver-memory MB and --driver-budget S (run, league, try); `each` names the worlds in the help
// ("each driver world", "the driver world").
void addDriverLimits(CLI::App* cmd, DriverLimitOptions& limits, const std::string& each);

}  // namespace pitwall::cli
