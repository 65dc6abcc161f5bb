// pitwall bridge: the cars of this host (simulated, or real ones with --ble) on an MQTT broker,
// under the seed's topic tree, executing the intents other clients send (docs/mqtt.md).
#include <iostream>
#include <memory>

#include "engine/cli/commands.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/session.hpp"
#include "engine/core/log.hpp"

namespace pitwall::cli {

int bridge(const BridgeOptions& options) {
  // The broker given here is where this host's cars go, not where remote cars come from.
  CarSource local = options;
  local.mqtt = {};
  auto made = Session::open(local, false, "bridge");
  if (!made) return 2;
  Session& session = *made;
  if (options.view) {
    if (int status = session.startView(*options.view, options.ble ? "ble" : "simulator", "bridge");
        status != 0)
      return status;
  }
  if (int status = session.connectCars("bridge"); status != 0) return status;
  if (int status = session.startBridge(options.mqtt, options.hostId, options.readOnly, "bridge");
      status != 0) {
    session.finish();
    session.loop().run();
    return status;
  }
  log::info("pitwall", "bridging " + std::to_string(session.fleet().cars().size()) + " car" +
                           (session.fleet().cars().size() == 1 ? "" : "s") + " as host " +
                           session.bridge()->host() + " on " + options.mqtt.url +
                           "; Ctrl-C to stop");
  if (options.duration)
    session.loop().after(fromSeconds(*options.duration), [&] {
      log::info("pitwall", "the bridge's duration is over: stopping the cars");
      session.finish();
    });
  session.loop().run();  // ends through Session::finish: SIGINT, SIGTERM, --duration
  return session.interrupted() ? 130 : 0;
}

Command addBridgeCommand(CLI::App& app) {
  auto bridge = std::make_shared<BridgeOptions>();
  auto* cmd = app.add_subcommand("bridge",
                                 "Publish the cars (simulated, or --ble) on an MQTT broker "
                                 "and execute intents (docs/mqtt.md)");
  addCarSource(cmd, *bridge, "before the bridge starts");
  addMqtt(cmd, bridge->mqtt, bridge->mqttTimeout, "where the cars are published")->required();
  cmd->add_option("--host-id", bridge->hostId,
                  "The <host> of Anki/Host/<host>/… (default: this machine's host name)");
  addView(cmd, bridge->view);
  cmd->add_flag("--read-only", bridge->readOnly, "Publish only; never execute intents");
  cmd->add_option("--duration", bridge->duration, "Stop after this many seconds")
      ->check(CLI::PositiveNumber);
  return {cmd, [bridge] { return cli::bridge(*bridge); }};
}

}  // namespace pitwall::cli
