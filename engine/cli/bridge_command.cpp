// pitwall bridge: the cars of this host (simulated, or real ones with --ble) on an MQTT broker,
// under the seed's topic tree, executing the intents other clients send (docs/mqtt.md).
#include <iostream>
#include <memory>

#include "engine/cli/commands.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/session.hpp"
#include "engine/core/log.hpp"
#include "engine/transport/mqtt_client.hpp"

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
  // "bridging" only once the broker has taken the connection: a broker that is down is waited
  // for (the client retries with backoff), and the log says so.
  const std::size_t count = session.fleet().cars().size();
  const std::string cars = std::to_string(count) + (count == 1 ? " car" : " cars");
  const std::string host = session.bridge()->host();
  auto bridging = [&options, cars, host] {
    log::info("pitwall", "bridging " + cars + " as host " + host + " on " + options.mqtt.url +
                             "; Ctrl-C to stop");
  };
  MqttClient& client = *session.mqtt();
  if (client.state() == MqttClient::State::Connected) {
    bridging();
  } else {
    const std::string& why = client.lastFailure();
    log::warn("pitwall", "waiting for the broker at " + options.mqtt.url + " (" +
                             (why.empty() ? std::string("no answer yet") : why) + "), retrying; " +
                             (count == 1 ? "the car is" : "the " + cars + " are") +
                             " bridged once it accepts the connection; Ctrl-C to stop");
    client.onConnected = [bridgeConnected = client.onConnected, bridging, said = false]() mutable {
      if (bridgeConnected) bridgeConnected();
      if (!said) bridging();
      said = true;
    };
  }
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
