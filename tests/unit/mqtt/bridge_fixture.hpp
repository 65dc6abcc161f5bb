#pragma once
// The set-up of the MqttBridge tests (bridge_test.cpp, bridge_limits_test.cpp): a real
// mosquitto broker (tests/support/mosquitto_broker.hpp), two simulated cars on the oval driven in
// real time on the one real-clock loop and published under the seed's topic tree, and an observer
// client that sends intents and records everything under Anki/#.
#include "engine/mqtt/bridge.hpp"

#include <doctest/doctest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "engine/protocol/anki/codec.hpp"
#include "engine/sim/grid.hpp"
#include "engine/sim/track.hpp"
#include "engine/sim/world.hpp"
#include "engine/transport/sim_link.hpp"
#include "tests/support/hostile_payloads.hpp"
#include "tests/support/mosquitto_broker.hpp"
#include "tests/support/run_until.hpp"
#include "tests/support/sim_cars.hpp"

namespace pitwall::testing::bridge {

using Json = nlohmann::json;
using namespace std::chrono_literals;

const std::string kHost = "pit1";

inline BridgeOptions optionsFor(const std::string& host, bool readOnly = false) {
  BridgeOptions options;
  options.host = host;
  options.readOnly = readOnly;
  return options;
}

inline std::int64_t nowMs() {
  using namespace std::chrono;
  return duration_cast<milliseconds>(system_clock::now().time_since_epoch()).count();
}

struct Received {
  std::string topic, payload;
  bool retained;
  std::int64_t at;  // when it arrived (ms since the epoch)
};

// A plain MQTT client that records every message under its filter and sends intents.
struct Observer {
  MqttClient client;
  std::vector<Received> messages;
  int connects = 0;

  Observer(Loop& loop, const MosquittoBroker& broker, const std::string& filter = "Anki/#")
      : client(loop, MqttOptions::fromUrl(broker.url())) {
    client.onConnected = [this] { ++connects; };
    client.onMessage = [this](std::string_view t, std::string_view p, bool r) {
      messages.push_back({std::string(t), std::string(p), r, nowMs()});
    };
    client.subscribe(filter, 1);
    client.subscribe("pitwall/test/#", 1);
    client.connect();
  }

  std::vector<const Received*> on(const std::string& topic) const {
    std::vector<const Received*> out;
    for (const auto& m : messages)
      if (m.topic == topic) out.push_back(&m);
    return out;
  }
  bool has(const std::string& topic) const { return !on(topic).empty(); }
  const Received* last(const std::string& topic) const {
    auto all = on(topic);
    return all.empty() ? nullptr : all.back();
  }
  // The last payload on `topic` as JSON (null when none came).
  Json json(const std::string& topic) const {
    auto* m = last(topic);
    return m ? Json::parse(m->payload) : Json();
  }
  std::size_t count(const std::string& topic) const { return on(topic).size(); }

  void send(const std::string& topic, const std::string& payload, bool retain = false) {
    REQUIRE(client.publish(topic, payload, 1, retain));
  }
  // A round trip through the broker: everything this client published before it has been
  // handled by the broker (and forwarded to subscribers) when the marker comes back.
  bool roundTrip(Loop& loop) {
    static int n = 0;
    std::string topic = "pitwall/test/marker" + std::to_string(++n);
    if (!client.publish(topic, "{}", 1)) return false;
    return runUntil(loop, [&] { return has(topic); });
  }
};

struct SentFrame {
  AnkiCar* car;
  anki::Message message;
};

// One host: a world with two simulated cars, its fleet, its client and its bridge.
struct Host {
  Loop& loop;
  sim::World world;
  Fleet fleet;
  std::vector<SentFrame> tx;  // every command sent to a car, recorded before the bridge sees it
  Subscription watch;
  std::unique_ptr<MqttClient> client;
  std::unique_ptr<MqttBridge> bridge;
  std::int64_t connectedAt = 0, lostAt = 0;  // the client's last connection and loss (ms)
  BridgeOptions bridgeOptions;

  Host(Loop& l, const MosquittoBroker& broker, bool readOnly = false)
      : Host(l, broker, optionsFor(kHost, readOnly)) {}
  Host(Loop& l, const MosquittoBroker& broker, BridgeOptions o)
      : loop(l), world(l, *sim::loadLayout("oval"), 7), fleet(l), bridgeOptions(std::move(o)) {
    for (int i = 0; i < 2; ++i)
      testing::addSimulatedCar(loop, fleet, world, sim::gridSpec(world.track(), i));
    watch = fleet.frames.connect([this](AnkiCar& car, AnkiCar::Direction d,
                                        std::span<const std::uint8_t>, const anki::Message& m) {
      if (d == AnkiCar::Direction::Tx) tx.push_back({&car, m});
    });
    REQUIRE(runUntil(loop, [&] { return fleet.connectedCount() == 2; }));
    startBridge(broker);
  }

  // The CLI's wiring (engine/cli/session.cpp Session::startBridge), with simulated cars only.
  void startBridge(const MosquittoBroker& broker) {
    auto options = MqttOptions::fromUrl(broker.url());
    options.will = MqttBridge::will(kHost);
    client = std::make_unique<MqttClient>(loop, options);
    CarConnections connections;
    connections.connectAll = [this] {
      for (auto* car : fleet.cars())
        if (auto* sim = dynamic_cast<SimLink*>(&car->link()); sim && !sim->connected())
          sim->connect();
    };
    connections.disconnectAll = [this] {
      for (auto* car : fleet.cars())
        if (car->state().connected) (void)car->disconnect();
    };
    bridge =
        std::make_unique<MqttBridge>(loop, fleet, *client, bridgeOptions, std::move(connections));
    auto bridgeConnected = client->onConnected;
    client->onConnected = [this, bridgeConnected] {
      connectedAt = nowMs();  // before the bridge publishes anything on this connection
      bridgeConnected();
    };
    client->onDisconnected = [this](const std::string&, bool) { lostAt = nowMs(); };
    client->connect();
    REQUIRE(runUntil(loop, [&] { return client->state() == MqttClient::State::Connected; }));
  }

  AnkiCar& car(int i) { return *fleet.cars().at(i); }
  sim::SimCar& simCar(int i) { return *world.cars().at(i); }
  std::string id(int i) { return bridge->carIdOf(car(i)); }
  std::string carTopic(int i, const std::string& rest) { return "Anki/Car/" + id(i) + "/" + rest; }

  template <typename M>
  std::vector<M> sent(int i) {
    std::vector<M> out;
    for (const auto& f : tx)
      if (f.car == &car(i))
        if (auto* m = std::get_if<M>(&f.message)) out.push_back(*m);
    return out;
  }
};

const std::string kHostIntent = "Anki/Host/" + kHost + "/I";
const std::string kIntentError = "Anki/Host/" + kHost + "/S/IntentError";
const std::string kHostStatus = "Anki/Host/" + kHost + "/S/HostStatus";
const std::string kCars = "Anki/Host/" + kHost + "/S/Cars";

inline std::string hex(const anki::Frame& frame) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (auto b : frame.span()) {
    out += digits[b >> 4];
    out += digits[b & 0xf];
  }
  return out;
}

inline std::vector<std::string> sorted(std::vector<std::string> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// Waits until the observer has seen the bridge online with both cars listed.
inline void waitForCars(Loop& loop, Observer& o, Host& h) {
  REQUIRE(runUntil(loop, [&] {
    auto cars = o.json(kCars);
    return o.json(kHostStatus) == Json{{"value", true}} && cars.is_array() && cars.size() == 2;
  }));
  CHECK(o.json(kCars).get<std::vector<std::string>>() == sorted({h.id(0), h.id(1)}));
}

// The usual set-up: a private broker, an observer subscribed to the whole tree, and a bridge of
// two simulated cars that the observer has seen published.
struct Bridged {
  MosquittoBroker broker;
  Loop loop{ClockKind::Real};
  Observer o{loop, broker};
  bool observing = runUntil(loop, [this] { return o.connects == 1; });
  Host h{loop, broker};
  Bridged() {
    REQUIRE(observing);
    waitForCars(loop, o, h);
  }
};

}  // namespace pitwall::testing::bridge
