// pitwall sim-robot KIND: a simulated seed robot listening on loopback (docs/robots.md).
#include <iostream>
#include <memory>

#include "engine/cli/commands.hpp"
#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"

namespace pitwall::cli {

int simRobot(const SimRobotOptions& options) {
  if (options.kind == "mindroad") return simRobotMindroad(options);
  if (options.kind == "alphabot") return simRobotAlphabot(options);
  return fail("sim-robot", "unknown robot '" + options.kind + "'; known: mindroad, alphabot");
}

Command addSimRobotCommand(CLI::App& app) {
  auto robot = std::make_shared<SimRobotOptions>();
  auto* cmd = app.add_subcommand(
      "sim-robot", "Be a seed robot (mindroad or alphabot), simulated, listening on the network");
  cmd->add_option("kind", robot->kind, "mindroad or alphabot")->required();
  cmd->add_option("--listen", robot->listen,
                  "HOST:PORT to listen on (default 127.0.0.1:0: a free port, printed)");
  cmd->add_flag("--udp", robot->udp, "mindroad: UDP instead of TCP");
  cmd->add_option("--watchdog", robot->watchdog,
                  "mindroad: seconds without an instruction before the robot stops (0.5)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--seed", robot->seed, "Seed of the simulation's noise");
  cmd->add_option("--room", robot->room, "alphabot: a room file (docs/robots.md)");
  cmd->add_option("--duration", robot->duration, "Stop after this many seconds")
      ->check(CLI::PositiveNumber);
  return {cmd, [robot] { return cli::simRobot(*robot); }};
}

}  // namespace pitwall::cli
