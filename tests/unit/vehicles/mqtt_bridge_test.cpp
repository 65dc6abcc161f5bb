// MqttBridge against a real mosquitto broker (tests/support/mosquitto_broker.hpp): two simulated
// cars on the oval, driven in real time on the one real-clock loop, published under the seed's
// topic tree; intents sent by an observer client that also records everything under Anki/#.
#include "engine/vehicles/mqtt_bridge.hpp"

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

using namespace pitwall;
using namespace std::chrono_literals;
using pitwall::testing::hostilePayloads;
using pitwall::testing::MosquittoBroker;
using pitwall::testing::runFor;
using pitwall::testing::runUntil;
using Json = nlohmann::json;

namespace {

const std::string kHost = "pit1";

BridgeOptions optionsFor(const std::string& host, bool readOnly = false) {
  BridgeOptions options;
  options.host = host;
  options.readOnly = readOnly;
  return options;
}

std::int64_t nowMs() {
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
  std::unique_ptr<MqttClient> client;
  std::unique_ptr<MqttBridge> bridge;
  std::int64_t connectedAt = 0, lostAt = 0;  // the client's last connection and loss (ms)
  BridgeOptions bridgeOptions;

  Host(Loop& l, const MosquittoBroker& broker, bool readOnly = false)
      : Host(l, broker, optionsFor(kHost, readOnly)) {}
  Host(Loop& l, const MosquittoBroker& broker, BridgeOptions o)
      : loop(l), world(l, *sim::loadLayout("oval"), 7), fleet(l), bridgeOptions(std::move(o)) {
    for (int i = 0; i < 2; ++i) fleet.addSimulated(world, sim::gridSpec(world.track(), i));
    fleet.onFrame = [this](AnkiCar& car, AnkiCar::Direction d, std::span<const std::uint8_t>,
                           const anki::Message& m) {
      if (d == AnkiCar::Direction::Tx) tx.push_back({&car, m});
    };
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

std::string hex(const anki::Frame& frame) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (auto b : frame.span()) {
    out += digits[b >> 4];
    out += digits[b & 0xf];
  }
  return out;
}

std::vector<std::string> sorted(std::vector<std::string> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// Waits until the observer has seen the bridge online with both cars listed.
void waitForCars(Loop& loop, Observer& o, Host& h) {
  REQUIRE(runUntil(loop, [&] {
    auto cars = o.json(kCars);
    return o.json(kHostStatus) == Json{{"value", true}} && cars.is_object() &&
           cars["value"].size() == 2;
  }));
  CHECK(o.json(kCars)["value"].get<std::vector<std::string>>() == sorted({h.id(0), h.id(1)}));
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

}  // namespace

TEST_CASE_FIXTURE(
    Bridged,
    "mqtt bridge: a speed intent drives the simulated cars and their events are published") {
  o.send(kHostIntent, R"({"type":"speed","speed":600,"acceleration":1000})");
  auto seen = [&](int i) {
    for (const char* rest : {"E/speed", "E/track_piece_id", "E/frame", "S/Speed/Actual"})
      if (!o.has(h.carTopic(i, rest))) return false;
    return o.json(h.carTopic(i, "S/Speed/Desired"))["value"] == 600;
  };
  REQUIRE(runUntil(loop, [&] { return seen(0) && seen(1); }));
  for (int i = 0; i < 2; ++i) {
    CAPTURE(i);
    CHECK(h.simCar(i).truth().speed_mm_s > 0);
    CHECK(h.car(i).state().speed_mm_s > 0);
    CHECK(h.car(i).state().target_speed_mm_s == 600);
    // events are not retained, status is
    CHECK_FALSE(o.last(h.carTopic(i, "E/speed"))->retained);
    auto piece = o.json(h.carTopic(i, "E/track_piece_id"));
    CHECK(piece["value"].is_number_integer());
    CHECK(piece["timestamp"].is_number_integer());
    // E/frame carries the frame itself: it decodes to a vehicle message
    auto frame = topics::readFrameEvent(o.last(h.carTopic(i, "E/frame"))->payload);
    REQUIRE(frame.ok());
    CHECK(anki::decode(*frame).ok());
  }
  CHECK(h.bridge->stats().intents == 1);
  CHECK(h.bridge->stats().rejected == 0);
  CHECK_FALSE(o.has(kIntentError));
}

TEST_CASE_FIXTURE(Bridged,
                  "mqtt bridge: a late subscriber gets the retained status and no stale events") {
  // Events happen (and would be in the broker's store if they were retained); then the cars stop.
  REQUIRE(h.car(0).setSpeed(500).ok());
  REQUIRE(runUntil(loop, [&] { return o.has(h.carTopic(0, "E/speed")); }));
  REQUIRE(h.car(0).setSpeed(0, 25000).ok());
  REQUIRE(runUntil(loop, [&] { return h.simCar(0).truth().speed_mm_s == 0; }));
  REQUIRE(o.roundTrip(loop));

  Observer late(loop, broker);
  REQUIRE(runUntil(loop, [&] { return late.connects == 1; }));
  REQUIRE(late.roundTrip(loop));  // the retained messages come before the marker
  CHECK(late.json(kHostStatus) == Json{{"value", true}});
  CHECK(late.last(kHostStatus)->retained);
  REQUIRE(late.has(kCars));
  CHECK(late.last(kCars)->retained);
  CHECK(late.json(kCars)["value"].get<std::vector<std::string>>() == sorted({h.id(0), h.id(1)}));
  for (int i = 0; i < 2; ++i) {
    CAPTURE(i);
    auto* info = late.last(h.carTopic(i, "S/Information"));
    REQUIRE(info);
    CHECK(info->retained);
    auto j = Json::parse(info->payload);
    CHECK(j["identifier"] == h.car(i).identity().identifier);
    CHECK(j["modelId"] == h.car(i).identity().model_id);
    CHECK(j["name"] == h.car(i).identity().name);
    auto* status = late.last(h.carTopic(i, "S/CarStatus"));
    REQUIRE(status);
    CHECK(status->retained);
    CHECK(Json::parse(status->payload)["online"] == true);
    CHECK(late.last(h.carTopic(i, "S/DiscoveryTime"))->retained);
  }
  CHECK(late.json(h.carTopic(0, "S/Speed/Desired"))["value"] == 0);
  // An event is never replayed from the store; the first message on a status topic comes from
  // it (later ones may be live: the car still reports as it comes to rest).
  std::set<std::string> status;
  for (const auto& m : late.messages) {
    CAPTURE(m.topic);
    if (m.topic.find("/E/") != std::string::npos)
      CHECK_FALSE(m.retained);
    else if (m.topic.starts_with("Anki/") && status.insert(m.topic).second)
      CHECK(m.retained);
  }
}

TEST_CASE_FIXTURE(
    Bridged, "mqtt bridge: every intent type is executed on one car, on all cars and on the host") {
  const std::string one = h.carTopic(0, "I");

  SUBCASE("speed") {
    o.send(one, R"({"type":"speed","speed":700,"acceleration":2000})");
    REQUIRE(runUntil(loop, [&] { return !h.sent<anki::SetSpeed>(0).empty(); }));
    CHECK(h.sent<anki::SetSpeed>(0).back() == anki::SetSpeed{700, 2000, false});
    CHECK(h.sent<anki::SetSpeed>(1).empty());
    REQUIRE(runUntil(loop, [&] { return h.simCar(0).truth().speed_mm_s > 0; }));
    CHECK(h.simCar(1).truth().speed_mm_s == 0);
  }
  SUBCASE("lane, with pitwall's optional lateral speed and acceleration") {
    REQUIRE(h.car(0).setSpeed(500).ok());
    o.send(one,
           R"({"type":"lane","offset":23,"horizontalSpeed":250,"horizontalAcceleration":2000})");
    REQUIRE(runUntil(loop, [&] { return !h.sent<anki::ChangeLane>(0).empty(); }));
    CHECK(h.sent<anki::ChangeLane>(0).back() == anki::ChangeLane{250, 2000, 23.0f, 0, 0});
    REQUIRE(runUntil(loop, [&] { return o.has(h.carTopic(0, "S/Lane/Desired")); }));
    CHECK(o.json(h.carTopic(0, "S/Lane/Desired"))["value"] == 23.0);
    double start = h.simCar(0).truth().offset_mm;
    REQUIRE(runUntil(loop, [&] { return std::abs(h.simCar(0).truth().offset_mm - start) > 5; }));
    // without the optional keys: AnkiCar::changeLane's defaults
    o.send(one, R"({"type":"lane","offset":-23})");
    REQUIRE(runUntil(loop, [&] { return h.sent<anki::ChangeLane>(0).size() == 2; }));
    CHECK(h.sent<anki::ChangeLane>(0).back() ==
          anki::ChangeLane{kDefaultLaneSpeed, kDefaultLaneAccel, -23.0f, 0, 0});
  }
  SUBCASE("turn") {
    REQUIRE(h.car(0).setSpeed(400).ok());
    o.send(one, R"({"type":"turn","turnType":3,"trigger":0})");
    REQUIRE(runUntil(loop, [&] { return !h.sent<anki::Turn>(0).empty(); }));
    CHECK(h.sent<anki::Turn>(0).back() ==
          anki::Turn{anki::TurnType::UTurn, anki::TurnTrigger::Immediate});
  }
  SUBCASE("battery, version and ping are answered on the car's status") {
    // (a car asks for its version and battery itself when it connects)
    auto batteries = h.sent<anki::BatteryRequest>(0).size();
    auto versions = h.sent<anki::VersionRequest>(0).size();
    auto others = h.sent<anki::BatteryRequest>(1).size();
    o.send(one, R"({"type":"battery"})");
    o.send(one, R"({"type":"version"})");
    o.send(one, R"({"type":"ping"})");
    REQUIRE(runUntil(loop, [&] {
      return o.has(h.carTopic(0, "S/BatteryLevel")) && o.has(h.carTopic(0, "S/Version")) &&
             o.has(h.carTopic(0, "S/PingResponse"));
    }));
    REQUIRE(h.car(0).state().battery_mv > 0);
    CHECK(o.json(h.carTopic(0, "S/BatteryLevel"))["value"] == h.car(0).state().battery_mv);
    CHECK(o.json(h.carTopic(0, "S/Version"))["value"] == h.simCar(0).spec().version);
    auto ping = o.json(h.carTopic(0, "S/PingResponse"));
    REQUIRE(ping["rtt_ms"].is_number());
    CHECK(ping["rtt_ms"].get<double>() > 0);
    CHECK(h.sent<anki::BatteryRequest>(0).size() == batteries + 1);
    CHECK(h.sent<anki::VersionRequest>(0).size() == versions + 1);
    CHECK(h.sent<anki::PingRequest>(0).size() == 1);
    CHECK(h.sent<anki::BatteryRequest>(1).size() == others);
    CHECK(h.sent<anki::PingRequest>(1).empty());
  }
  SUBCASE("message: any command as its frame") {
    o.send(one,
           R"({"type":"message","frame":")" + hex(anki::encode(anki::SetLights{0x44})) + R"("})");
    REQUIRE(runUntil(loop, [&] { return !h.sent<anki::SetLights>(0).empty(); }));
    CHECK(h.sent<anki::SetLights>(0).back() == anki::SetLights{0x44});
    o.send(one,
           R"({"type":"message","frame":")" + hex(anki::encode(anki::SetOffset{-68})) + R"("})");
    REQUIRE(runUntil(loop, [&] { return !h.sent<anki::SetOffset>(0).empty(); }));
    CHECK(h.car(0).state().offset_mm == -68);
    REQUIRE(runUntil(loop, [&] { return o.has(h.carTopic(0, "S/Lane/Desired")); }));
    CHECK(o.json(h.carTopic(0, "S/Lane/Desired"))["value"] == -68.0);
  }
  SUBCASE("Anki/Car/all/I and Anki/Host/<host>/I reach every car") {
    o.send("Anki/Car/all/I", R"({"type":"speed","speed":300,"acceleration":1000})");
    REQUIRE(runUntil(loop, [&] {
      return !h.sent<anki::SetSpeed>(0).empty() && !h.sent<anki::SetSpeed>(1).empty();
    }));
    CHECK(h.sent<anki::SetSpeed>(0).back().speed_mm_s == 300);
    CHECK(h.sent<anki::SetSpeed>(1).back().speed_mm_s == 300);
    o.send(kHostIntent, R"({"type":"speed","speed":0,"acceleration":12500})");
    REQUIRE(runUntil(loop, [&] {
      return h.sent<anki::SetSpeed>(0).size() == 2 && h.sent<anki::SetSpeed>(1).size() == 2;
    }));
    CHECK(h.sent<anki::SetSpeed>(0).back() == anki::SetSpeed{0, 12500, false});
    CHECK(h.sent<anki::SetSpeed>(1).back() == anki::SetSpeed{0, 12500, false});
    CHECK(h.bridge->stats().intents == 2);
  }
  SUBCASE("connection false drops every car, connection true brings them back") {
    o.send(kHostIntent + "/connection", R"({"connecting":false})");
    REQUIRE(runUntil(loop, [&] { return h.fleet.connectedCount() == 0; }));
    REQUIRE(runUntil(loop, [&] {
      return o.json(kCars)["value"].empty() &&
             o.json(h.carTopic(0, "S/CarStatus"))["online"] == false &&
             o.json(h.carTopic(1, "S/CarStatus"))["online"] == false;
    }));
    CHECK(h.sent<anki::Disconnect>(0).size() == 1);
    CHECK(h.sent<anki::Disconnect>(1).size() == 1);
    CHECK_FALSE(h.simCar(0).truth().connected);
    o.send(kHostIntent + "/connection", R"({"connecting":true})");
    REQUIRE(runUntil(loop, [&] { return h.fleet.connectedCount() == 2; }));
    REQUIRE(runUntil(loop, [&] {
      return o.json(kCars)["value"].size() == 2 &&
             o.json(h.carTopic(0, "S/CarStatus"))["online"] == true &&
             o.json(h.carTopic(1, "S/CarStatus"))["online"] == true;
    }));
    CHECK(h.simCar(0).truth().connected);
  }
  CHECK_FALSE(o.has(kIntentError));
  CHECK(h.bridge->stats().rejected == 0);
}

TEST_CASE_FIXTURE(
    Bridged, "mqtt bridge: a malformed intent is answered on S/IntentError and sends nothing") {
  std::size_t framesBefore = h.tx.size();
  std::uint64_t out0 = h.car(0).state().frames_out, out1 = h.car(1).state().frames_out;
  const std::string one = h.carTopic(0, "I");
  const std::string speed = R"({"type":"speed","speed":600,"acceleration":1000})";

  struct Bad {
    std::string topic, payload;
    bool retain;
    std::string fragment;
  };
  std::vector<Bad> bad = {
      {one, R"({"type":"speed",)", false, "payload is not JSON"},
      {one, "[1,2]", false, "payload must be a JSON object, not an array"},
      {one, R"({"type":"fly"})", false, "unknown intent type \"fly\""},
      {one, R"({"type":"speed","speed":600})", false, "missing key \"acceleration\""},
      {one, R"({"type":"speed","speed":2000,"acceleration":1000})", false,
       "speed 2000 mm/s is out of range 0..1500 mm/s"},
      {kHostIntent, R"({"type":"lane","offset":-100.5})", false, "out of range -100..100 mm"},
      {"Anki/Car/all/I", R"({"type":"turn","turnType":5,"trigger":0})", false,
       "turnType 5 is out of range"},
      {one, R"({"type":"message","frame":"0xyz"})", false, "\"frame\""},
      {kHostIntent + "/connection", R"({"connecting":"yes"})", false,
       "\"connecting\" must be true or false"},
      {"Anki/Car/ffffffffffff/I", speed, false, "unknown car \"ffffffffffff\"; known cars: "},
  };
  for (std::size_t n = 0; n < bad.size(); ++n) {
    const auto& b = bad[n];
    CAPTURE(b.topic);
    CAPTURE(b.payload);
    o.send(b.topic, b.payload, b.retain);
    REQUIRE(runUntil(loop, [&] { return o.count(kIntentError) == n + 1; }));
    auto* m = o.last(kIntentError);
    CHECK_FALSE(m->retained);
    auto j = Json::parse(m->payload);
    CHECK(j["topic"] == b.topic);
    CHECK(j["error"].get<std::string>().find(b.fragment) != std::string::npos);
    CHECK(j["timestamp"].is_number_integer());
  }
  // The unknown car's error names the cars there are.
  REQUIRE(o.count(kIntentError) == bad.size());
  auto unknown =
      Json::parse(o.on(kIntentError)[bad.size() - 1]->payload)["error"].get<std::string>();
  CHECK(unknown.find(h.id(0)) != std::string::npos);
  CHECK(unknown.find(h.id(1)) != std::string::npos);

  // An intent for another host never reaches this bridge (it subscribes to its own host's topics
  // only): no answer at all. The next error proves the broker has delivered what came before.
  o.send("Anki/Host/pit2/I", speed);
  o.send("Anki/Car/ffffffffffff/I", speed);
  REQUIRE(runUntil(loop, [&] { return o.count(kIntentError) == bad.size() + 1; }));
  CHECK(Json::parse(o.last(kIntentError)->payload)["topic"] == "Anki/Car/ffffffffffff/I");

  CHECK(h.bridge->stats().rejected == bad.size() + 1);
  CHECK(h.bridge->stats().intents == 0);
  CHECK(h.tx.size() == framesBefore);
  CHECK(h.car(0).state().frames_out == out0);
  CHECK(h.car(1).state().frames_out == out1);
  CHECK(h.car(0).state().target_speed_mm_s == 0);

  // The bridge carries on.
  o.send(one, speed);
  REQUIRE(runUntil(loop, [&] { return !h.sent<anki::SetSpeed>(0).empty(); }));
  CHECK(h.sent<anki::SetSpeed>(0).back().speed_mm_s == 600);
  CHECK(h.bridge->stats().intents == 1);
}

TEST_CASE("mqtt bridge: a retained intent is rejected, not executed, when the bridge connects") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  Observer o(loop, broker);
  REQUIRE(runUntil(loop, [&] { return o.connects == 1; }));
  // Left in the broker's store by a careless client: it would run again on every reconnection.
  // (MQTT 3.1.1 clears the retain flag when it forwards a message to a subscription that already
  // exists, so only the copy from the store is recognisable as retained.)
  o.send(kHostIntent, R"({"type":"speed","speed":600,"acceleration":1000})", true);
  REQUIRE(o.roundTrip(loop));
  Host h(loop, broker);
  REQUIRE(runUntil(loop, [&] { return o.has(kIntentError); }));
  auto j = o.json(kIntentError);
  CHECK(j["topic"] == kHostIntent);
  CHECK(j["error"].get<std::string>().find("retained intents are not executed") !=
        std::string::npos);
  REQUIRE(o.roundTrip(loop));
  CHECK(o.count(kIntentError) == 1);
  CHECK(h.sent<anki::SetSpeed>(0).empty());
  CHECK(h.sent<anki::SetSpeed>(1).empty());
  CHECK(h.bridge->stats().intents == 0);
  CHECK(h.bridge->stats().rejected == 1);
}

TEST_CASE_FIXTURE(
    Bridged, "mqtt bridge: a single-car intent for a car another online host owns is left to it") {
  const std::string speed = R"({"type":"speed","speed":600,"acceleration":1000})";
  std::size_t framesBefore = h.tx.size();

  o.send("Anki/Host/other/S/HostStatus", R"({"value":true})", true);
  o.send("Anki/Host/other/S/Cars", R"({"timestamp":1,"value":["xyz"]})", true);
  o.send("Anki/Car/xyz/I", speed);
  // a marker: an error for a car nobody owns, which comes after whatever xyz caused
  o.send("Anki/Car/nobody/I", speed);
  REQUIRE(runUntil(loop, [&] { return o.count(kIntentError) >= 1; }));
  REQUIRE(o.roundTrip(loop));
  CHECK(o.count(kIntentError) == 1);
  CHECK(Json::parse(o.last(kIntentError)->payload)["topic"] == "Anki/Car/nobody/I");

  // The other host goes offline: its cars are nobody's, and this bridge answers.
  o.send("Anki/Host/other/S/HostStatus", R"({"value":false})", true);
  o.send("Anki/Car/xyz/I", speed);
  REQUIRE(runUntil(loop, [&] { return o.count(kIntentError) == 2; }));
  auto j = o.json(kIntentError);
  CHECK(j["topic"] == "Anki/Car/xyz/I");
  CHECK(j["error"].get<std::string>().find("unknown car \"xyz\"") != std::string::npos);
  CHECK(h.tx.size() == framesBefore);

  // The other host's list does not hide this host's own cars, even when it names them.
  o.send("Anki/Host/other/S/HostStatus", R"({"value":true})", true);
  o.send("Anki/Host/other/S/Cars", R"({"timestamp":2,"value":[")" + h.id(1) + R"("]})", true);
  o.send(h.carTopic(1, "I"), speed);
  REQUIRE(runUntil(loop, [&] { return !h.sent<anki::SetSpeed>(1).empty(); }));
}

TEST_CASE(
    "mqtt bridge: after a broker restart the bridge republishes its status, without stale "
    "events") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  Observer o(loop, broker);
  REQUIRE(runUntil(loop, [&] { return o.connects == 1; }));
  Host h(loop, broker);
  waitForCars(loop, o, h);
  REQUIRE(h.car(0).setSpeed(600).ok());
  REQUIRE(h.car(1).setSpeed(600).ok());
  REQUIRE(runUntil(loop, [&] { return o.has(h.carTopic(0, "E/speed")); }));

  broker.stop();
  REQUIRE(runUntil(loop, [&] { return h.client->state() != MqttClient::State::Connected; }));
  auto down = h.lostAt;
  REQUIRE(down > 0);
  auto dropped = h.bridge->stats().dropped;
  auto republished = h.bridge->stats().republished;
  // The cars go on driving: their events have nowhere to go.
  REQUIRE(runUntil(loop, [&] { return h.bridge->stats().dropped > dropped + 20; }));
  broker.start();  // an empty broker: no retained store
  REQUIRE(runUntil(
      loop, [&] { return h.client->state() == MqttClient::State::Connected; }, 4s));
  auto up = h.connectedAt;
  REQUIRE(up > down);
  CHECK(h.bridge->stats().republished > republished);

  Observer late(loop, broker);
  REQUIRE(runUntil(loop, [&] { return late.connects == 1; }));
  REQUIRE(late.roundTrip(loop));
  CHECK(late.json(kHostStatus) == Json{{"value", true}});
  REQUIRE(late.has(kCars));
  CHECK(late.json(kCars)["value"].get<std::vector<std::string>>() == sorted({h.id(0), h.id(1)}));
  for (int i = 0; i < 2; ++i) {
    CHECK(late.has(h.carTopic(i, "S/Information")));
    CHECK(late.json(h.carTopic(i, "S/CarStatus"))["online"] == true);
    CHECK(late.json(h.carTopic(i, "S/Speed/Desired"))["value"] == 600);
  }
  // Events resume, and none of those from the time the broker was away arrives late.
  REQUIRE(runUntil(loop, [&] { return o.connects == 2; }));
  std::size_t before = o.messages.size();
  REQUIRE(runUntil(loop, [&] {
    for (std::size_t n = before; n < o.messages.size(); ++n)
      if (o.messages[n].topic == h.carTopic(1, "E/speed")) return true;
    return false;
  }));
  for (const auto& m : o.messages) {
    if (m.topic.find("/E/") == std::string::npos) continue;
    auto t = Json::parse(m.payload)["timestamp"].get<std::int64_t>();
    CAPTURE(m.topic);
    CHECK_FALSE((t > down && t < up));
  }
}

TEST_CASE("mqtt bridge: a read-only bridge publishes events and executes no intent") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  Observer o(loop, broker);
  REQUIRE(runUntil(loop, [&] { return o.connects == 1; }));
  Host h(loop, broker, /*readOnly=*/true);
  waitForCars(loop, o, h);
  std::size_t framesBefore = h.tx.size();

  o.send(kHostIntent, R"({"type":"speed","speed":600,"acceleration":1000})");
  o.send(h.carTopic(0, "I"), R"({"type":"speed","speed":2000,"acceleration":1000})");
  o.send(kHostIntent + "/connection", R"({"connecting":false})");
  REQUIRE(o.roundTrip(loop));
  runFor(loop, 200ms);
  CHECK(h.tx.size() == framesBefore);
  CHECK(h.fleet.connectedCount() == 2);
  CHECK(h.car(0).state().target_speed_mm_s == 0);
  CHECK_FALSE(o.has(kIntentError));
  CHECK(h.bridge->stats().intents == 0);
  CHECK(h.bridge->stats().rejected == 0);

  // What the cars do is still published.
  REQUIRE(h.car(0).setSpeed(500).ok());
  REQUIRE(runUntil(loop, [&] {
    return o.has(h.carTopic(0, "E/speed")) &&
           o.json(h.carTopic(0, "S/Speed/Desired"))["value"] == 500;
  }));
}

TEST_CASE("mqtt bridge: the broker publishes HostStatus false when a bridge's process dies") {
  MosquittoBroker broker;
  // A whole bridge with its cars in a child process, SIGKILLed: no DISCONNECT, the will is sent.
  pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    Loop childLoop(ClockKind::Real);
    sim::World world(childLoop, *sim::loadLayout("oval"), 7);
    Fleet fleet(childLoop);
    for (int i = 0; i < 2; ++i) fleet.addSimulated(world, sim::gridSpec(world.track(), i));
    auto options = MqttOptions::fromUrl(broker.url());
    options.will = MqttBridge::will(kHost);
    MqttClient client(childLoop, options);
    MqttBridge bridge(childLoop, fleet, client, optionsFor(kHost), {});
    client.connect();
    childLoop.after(std::chrono::seconds(10), [] { ::_exit(3); });
    childLoop.run();
    ::_exit(2);
  }
  Loop loop(ClockKind::Real);
  Observer o(loop, broker);
  bool ready = runUntil(loop, [&] {
    auto cars = o.json(kCars);
    return o.json(kHostStatus) == Json{{"value", true}} && cars.is_object() &&
           cars["value"].size() == 2;
  });
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  REQUIRE_MESSAGE(ready, "the child's bridge never published its two cars");
  REQUIRE(runUntil(loop, [&] { return o.json(kHostStatus) == Json{{"value", false}}; }));

  Observer late(loop, broker);
  REQUIRE(runUntil(loop, [&] { return late.connects == 1; }));
  REQUIRE(late.roundTrip(loop));
  REQUIRE(late.has(kHostStatus));
  CHECK(late.last(kHostStatus)->retained);
  CHECK(late.json(kHostStatus) == Json{{"value", false}});
}

TEST_CASE_FIXTURE(
    Bridged,
    "mqtt bridge: goOffline() publishes every car offline, no cars, and HostStatus false") {
  h.bridge->goOffline();
  REQUIRE(runUntil(loop, [&] { return o.json(kHostStatus) == Json{{"value", false}}; }));
  REQUIRE(o.roundTrip(loop));
  CHECK(o.json(kCars)["value"].empty());
  CHECK(o.json(h.carTopic(0, "S/CarStatus"))["online"] == false);
  CHECK(o.json(h.carTopic(1, "S/CarStatus"))["online"] == false);
  // The goodbye is the last word: a car's frame after it (a battery answer, a late status) is not
  // published over it, and an intent is not executed.
  const std::string intent = h.carTopic(1, "I");
  auto bridgeSaid = [&] {
    std::size_t n = 0;
    for (const auto& m : o.messages) n += m.topic.starts_with("Anki/") && m.topic != intent;
    return n;
  };
  const auto published = bridgeSaid();
  const auto commands = h.tx.size();
  const auto framesIn = h.car(0).state().frames_in;
  REQUIRE(h.car(0).requestBattery());
  o.send(intent, R"({"type":"speed","speed":500,"acceleration":1000})");
  REQUIRE(runUntil(loop, [&] { return h.car(0).state().frames_in > framesIn; }));
  REQUIRE(o.roundTrip(loop));
  REQUIRE(o.roundTrip(loop));
  CHECK(bridgeSaid() == published);
  CHECK(h.tx.size() == commands + 1);  // only the battery request made above
  h.client->disconnect();              // clean: no will, the status above stays
  Observer late(loop, broker);
  REQUIRE(runUntil(loop, [&] { return late.connects == 1; }));
  REQUIRE(late.roundTrip(loop));
  CHECK(late.json(kHostStatus) == Json{{"value", false}});
  CHECK(late.json(kCars)["value"].empty());
  CHECK(late.json(h.carTopic(0, "S/CarStatus"))["online"] == false);
}

TEST_CASE("mqtt bridge: a hostile intent is refused with a short error and the car still obeys") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  Observer o(loop, broker);
  REQUIRE(runUntil(loop, [&] { return o.connects == 1; }));
  // Every refusal answered and every intent executed: the rate limits have a test of their own.
  auto options = optionsFor(kHost);
  options.intents = options.errors = RateLimit{1000, 1000};
  Host h(loop, broker, options);
  waitForCars(loop, o, h);
  const std::string one = h.carTopic(0, "I");
  int speed = 100;
  // The bridge is alive and the car obeys: a valid intent after each hostile one is executed.
  auto obeys = [&] {
    ++speed;
    o.send(one, R"({"type":"speed","speed":)" + std::to_string(speed) + R"(,"acceleration":1000})");
    return runUntil(loop, [&] {
      auto sent = h.sent<anki::SetSpeed>(0);
      return !sent.empty() && sent.back().speed_mm_s == speed;
    });
  };

  std::size_t errors = 0;
  for (const auto& bad : hostilePayloads()) {
    CAPTURE(bad.name);
    std::size_t frames = h.tx.size();
    o.send(one, bad.payload);
    REQUIRE(runUntil(loop, [&] { return o.count(kIntentError) == errors + 1; }));
    ++errors;
    const auto& answer = o.last(kIntentError)->payload;
    CHECK(answer.size() <= topics::kMaxIntentError);
    auto j = Json::parse(answer);  // valid JSON, valid UTF-8
    CHECK(j["topic"] == one);
    auto error = j["error"].get<std::string>();
    CAPTURE(error);
    CHECK(error.find(bad.error) != std::string::npos);
    // at most 80 bytes of the payload (escaped: at most 4 bytes each), plus our words
    CHECK(error.size() < 600);
    CHECK(h.tx.size() == frames);  // nothing was sent to a car
    CHECK(obeys());
  }
  // Invalid bytes are shown escaped, as \xNN.
  auto utf8 = Json::parse(o.on(kIntentError)[4]->payload)["error"].get<std::string>();
  CHECK(utf8.find("\\xff") != std::string::npos);

  // On the limits, not beyond them: executed.
  o.send(one, pitwall::testing::paddedSpeedIntent(64 * 1024, 1234));
  REQUIRE(runUntil(loop, [&] { return h.sent<anki::SetSpeed>(0).back().speed_mm_s == 1234; }));
  o.send(one, pitwall::testing::deepSpeedIntent(64, 1235));
  REQUIRE(runUntil(loop, [&] { return h.sent<anki::SetSpeed>(0).back().speed_mm_s == 1235; }));

  // An empty payload clears a retained message: ignored without an answer.
  o.send(one, "");
  CHECK(obeys());
  // What the bridge reads of other hosts (their cars and status) is read with the same care.
  for (const auto& bad : hostilePayloads()) {
    o.send("Anki/Host/pit9/S/Cars", bad.payload);
    o.send("Anki/Host/pit9/S/HostStatus", bad.payload);
  }
  CHECK(obeys());
  CHECK(o.count(kIntentError) == errors);
  CHECK(h.bridge->stats().faults == 0);
  CHECK(h.bridge->stats().rejected == errors);
}

TEST_CASE("mqtt bridge: a flood of intents to a car is cut to its rate, with one error a second") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  Observer o(loop, broker);
  REQUIRE(runUntil(loop, [&] { return o.connects == 1; }));
  Host h(loop, broker);  // the default limits: 50 intents a second per car, 20 at once
  waitForCars(loop, o, h);
  const std::string one = h.carTopic(0, "I");
  const RateLimit limit = h.bridgeOptions.intents;
  CHECK(limit.perSecond == 50);
  CHECK(limit.burst == 20);

  constexpr int kFlood = 1000;
  auto start = loop.now();
  for (int i = 0; i < kFlood; ++i)
    o.send(one,
           R"({"type":"speed","speed":)" + std::to_string(i % 1500) + R"(,"acceleration":1000})");
  const auto& stats = h.bridge->stats();
  REQUIRE(runUntil(
      loop, [&] { return stats.intents + stats.throttled == kFlood; }, 20s));
  double seconds = toSeconds(loop.now() - start);
  CAPTURE(seconds);
  auto executed = h.sent<anki::SetSpeed>(0).size();
  CHECK(executed == stats.intents);
  CHECK(executed <= limit.burst + limit.perSecond * seconds + 1);
  CHECK(stats.throttled > 0);
  CHECK(h.sent<anki::SetSpeed>(1).empty());

  // Every dropped intent is accounted for, in at most one error a second (the first at once).
  auto droppedIn = [&] {
    std::uint64_t n = 0;
    for (const auto* m : o.on(kIntentError)) {
      auto error = Json::parse(m->payload)["error"].get<std::string>();
      CHECK(error.find(" for car " + h.id(0) + " w") != std::string::npos);
      CHECK(error.find("at most 50 a second, 20 at once") != std::string::npos);
      n += std::stoull(error);
    }
    return n;
  };
  REQUIRE(runUntil(loop, [&] { return droppedIn() == stats.throttled; }));
  seconds = toSeconds(loop.now() - start);
  CHECK(o.count(kIntentError) >= 1);
  CHECK(o.count(kIntentError) <= 2 + seconds);
  CHECK(Json::parse(o.last(kIntentError)->payload)["topic"] == one);

  // The bucket refills at 50 a second: after 50 ms, the car obeys again.
  runFor(loop, 50ms);
  o.send(one, R"({"type":"speed","speed":1499,"acceleration":1000})");
  REQUIRE(runUntil(loop, [&] { return h.sent<anki::SetSpeed>(0).back().speed_mm_s == 1499; }));
}

TEST_CASE_FIXTURE(Bridged,
                  "mqtt bridge: a stop is never throttled, however full the flood before it") {
  const std::string one = h.carTopic(0, "I");
  constexpr int kFlood = 300;
  for (int i = 0; i < kFlood; ++i)
    o.send(one, R"({"type":"speed","speed":800,"acceleration":1000})");
  o.send(one, R"({"type":"speed","speed":0,"acceleration":12500})");
  const auto& stats = h.bridge->stats();
  REQUIRE(runUntil(
      loop, [&] { return stats.intents + stats.throttled == kFlood + 1; }, 20s));
  CHECK(stats.throttled > 0);  // the bucket was empty when the stop came
  auto speeds = h.sent<anki::SetSpeed>(0);
  REQUIRE_FALSE(speeds.empty());
  CHECK(speeds.back().speed_mm_s == 0);
}

TEST_CASE("mqtt bridge: a flood of bad intents gets a bounded number of answers") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  Observer o(loop, broker);
  REQUIRE(runUntil(loop, [&] { return o.connects == 1; }));
  Host h(loop, broker);  // the default: 10 answers a second, 20 at once
  waitForCars(loop, o, h);
  constexpr int kFlood = 500;
  auto start = loop.now();
  for (int i = 0; i < kFlood; ++i) o.send("Anki/Car/nobody" + std::to_string(i) + "/I", "[1]");
  const auto& stats = h.bridge->stats();
  REQUIRE(runUntil(
      loop, [&] { return stats.rejected == kFlood; }, 20s));
  // Every refusal is either answered or counted in a summary.
  auto accounted = [&] {
    std::uint64_t n = 0;
    for (const auto* m : o.on(kIntentError)) {
      auto error = Json::parse(m->payload)["error"].get<std::string>();
      n += error.find("rejected without an answer each") != std::string::npos ? std::stoull(error)
                                                                              : 1;
    }
    return n;
  };
  REQUIRE(runUntil(loop, [&] { return accounted() == kFlood; }));
  double seconds = toSeconds(loop.now() - start);
  CAPTURE(seconds);
  CHECK(stats.unanswered > 0);
  CHECK(o.count(kIntentError) <= 20 + 10 * seconds + 2 + seconds);
  auto last = Json::parse(o.last(kIntentError)->payload)["error"].get<std::string>();
  CHECK(last.find("(S/IntentError answers at most 10 a second, 20 at once); the last: unknown "
                  "car \"nobody") != std::string::npos);
  // and the bridge carries on
  o.send(h.carTopic(0, "I"), R"({"type":"speed","speed":321,"acceleration":1000})");
  REQUIRE(runUntil(loop, [&] { return !h.sent<anki::SetSpeed>(0).empty(); }));
}
