// pitwall sim-robot KIND: a simulated seed robot listening on loopback (docs/robots.md).
#include <iostream>

#include "engine/cli/commands.hpp"

namespace pitwall::cli {

int simRobot(const SimRobotOptions& options) {
  if (options.kind == "mindroad") return simRobotMindroad(options);
  if (options.kind == "alphabot") return simRobotAlphabot(options);
  std::cerr << "pitwall sim-robot: unknown robot '" << options.kind
            << "'; known: mindroad, alphabot\n";
  return 2;
}

}  // namespace pitwall::cli
