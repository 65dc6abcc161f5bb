// pitwall bridge: the cars of this host (simulated, or real ones with --ble) on an MQTT broker,
// under the seed's topic tree, executing the intents other clients send (docs/mqtt.md).
#include <iostream>

#include "engine/cli/commands.hpp"
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

}  // namespace pitwall::cli
