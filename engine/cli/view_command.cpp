// pitwall view --mqtt URL: a spectator's race view (docs/view.md "Spectators"). The cars that
// bridges on other hosts publish join as remote cars, read-only: nothing is ever published, no
// command is sent, and the end sends no stop (they are their bridges' cars).
#include <iostream>
#include <memory>

#include "engine/cli/commands.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/session.hpp"
#include "engine/core/log.hpp"

namespace pitwall::cli {

int view(const ViewOptions& options) {
  CarSource source = options;
  source.cars = 0;  // no simulated car: the world is only the layout drawn
  auto made = Session::open(source, false, "view");
  if (!made) return 2;
  Session& session = *made;
  session.spectate();
  if (int status = session.startView(options.view.value_or(""), "mqtt", "view"); status != 0)
    return status;
  if (int status = session.connectCars("view"); status != 0) return status;
  log::info("pitwall", "watching the cars on " + options.mqtt.url + " (read-only); Ctrl-C to stop");
  if (options.duration)
    session.loop().after(fromSeconds(*options.duration), [&] { session.finish(); });
  session.loop().run();  // ends through Session::finish: SIGINT, SIGTERM, --duration
  return session.interrupted() ? 130 : 0;
}

Command addViewCommand(CLI::App& app) {
  auto spectator = std::make_shared<ViewOptions>();
  auto* cmd = app.add_subcommand(
      "view", "Watch the cars that bridges publish on an MQTT broker in the race view, read-only");
  addMqtt(cmd, spectator->mqtt, spectator->mqttTimeout, "where bridges publish their cars")
      ->required();
  cmd->add_option("--track", spectator->track,
                  "The layout drawn: a name (oval, …) or a layout file (default oval)");
  addView(cmd, spectator->view);
  cmd->add_option("--duration", spectator->duration, "Stop after this many seconds")
      ->check(CLI::PositiveNumber);
  return {cmd, [spectator] { return cli::view(*spectator); }};
}

}  // namespace pitwall::cli
