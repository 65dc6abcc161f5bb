// RemoteCars against a real mosquitto broker: host A bridges two simulated cars (MqttBridge);
// host B, on the same real-clock loop, sees them as AnkiCars of its own fleet and drives them
// through intents.
#include "engine/mqtt/remote.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/mqtt/bridge.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "engine/sim/grid.hpp"
#include "engine/sim/track.hpp"
#include "engine/sim/world.hpp"
#include "tests/support/hostile_payloads.hpp"
#include "tests/support/mosquitto_broker.hpp"
#include "tests/support/run_until.hpp"
#include "tests/support/sim_cars.hpp"

using namespace pitwall;
using namespace std::chrono_literals;
using pitwall::testing::MosquittoBroker;
using pitwall::testing::runUntil;

namespace {

const std::string kHost = "hostA";

// Host A: two simulated cars published by a bridge; every command its cars are sent, recorded.
struct BridgedHost {
  Loop& loop;
  const MosquittoBroker& broker;
  sim::World world;
  Fleet fleet;
  std::vector<std::pair<AnkiCar*, anki::Message>> tx;
  Subscription watch;
  std::unique_ptr<MqttClient> client;
  std::unique_ptr<MqttBridge> bridge;

  BridgedHost(Loop& l, const MosquittoBroker& b)
      : loop(l), broker(b), world(l, *sim::loadLayout("oval"), 11), fleet(l) {
    for (int i = 0; i < 2; ++i)
      testing::addSimulatedCar(loop, fleet, world, sim::gridSpec(world.track(), i));
    watch = fleet.frames.connect([this](AnkiCar& car, AnkiCar::Direction d,
                                        std::span<const std::uint8_t>, const anki::Message& m) {
      if (d == AnkiCar::Direction::Tx) tx.emplace_back(&car, m);
    });
    REQUIRE(runUntil(loop, [&] { return fleet.connectedCount() == 2; }));
    startBridge();
  }

  // A fresh client and bridge (the first, or after the previous one went away).
  void startBridge() {
    bridge.reset();
    client.reset();
    auto options = MqttOptions::fromUrl(broker.url());
    options.will = MqttBridge::will(kHost);
    client = std::make_unique<MqttClient>(loop, options);
    BridgeOptions bridgeOptions;
    bridgeOptions.host = kHost;
    bridge = std::make_unique<MqttBridge>(loop, fleet, *client, bridgeOptions, CarConnections{});
    client->connect();
    REQUIRE(runUntil(loop, [&] { return client->state() == MqttClient::State::Connected; }));
  }
  // The process dies: no DISCONNECT, the broker sends the will.
  void crash() {
    bridge.reset();
    client.reset();
  }

  AnkiCar& car(int i) { return *fleet.cars().at(i); }
  sim::SimCar& simCar(int i) { return *world.cars().at(i); }
  AnkiCar* byName(const std::string& name) {
    for (auto* c : fleet.cars())
      if (c->identity().name == name) return c;
    return nullptr;
  }
};

// Host B: remote cars only.
struct RemoteHost {
  Fleet fleet;
  MqttClient client;
  RemoteCars remote;
  bool synced = false;
  std::optional<std::string> failed;
  std::vector<std::pair<std::string, std::string>> downs;  // car name, reason
  int changes = 0;
  Subscription watch;

  RemoteHost(Loop& loop, const MosquittoBroker& broker)
      : fleet(loop), client(loop, MqttOptions::fromUrl(broker.url())), remote(loop, fleet, client) {
    watch =
        fleet.connectionChanged.connect([this](AnkiCar& car, bool up, const std::string& reason) {
          if (!up) downs.emplace_back(car.identity().name, reason);
        });
    remote.onChange = [this] { ++changes; };
    remote.start([this] { synced = true; }, [this](const std::string& r) { failed = r; });
  }
  AnkiCar& car(int i) { return *fleet.cars().at(i); }
};

// A and B, with B's two remote cars online.
struct Pair {
  MosquittoBroker broker;
  Loop loop{ClockKind::Real};
  BridgedHost a{loop, broker};
  RemoteHost b{loop, broker};

  Pair() {
    REQUIRE(runUntil(loop, [&] { return b.synced && b.remote.onlineCount() == 2; }));
    REQUIRE(b.fleet.cars().size() == 2);
  }
  // A's car behind B's car i.
  AnkiCar& aOf(int i) {
    auto* c = a.byName(b.car(i).identity().name);
    REQUIRE(c);
    return *c;
  }
  // Sends a command on B's car i; true once A's car behind it has been sent `expected`. (B's
  // cars also ask for the version and battery whenever they connect: those intents may arrive
  // in between.)
  bool reaches(int i, const std::function<AnkiCar::Sent(AnkiCar&)>& command,
               const anki::Message& expected) {
    AnkiCar* target = &aOf(i);
    std::size_t before = a.tx.size();
    auto sent = command(b.car(i));
    if (!sent.ok()) FAIL(sent.error());
    bool arrived = runUntil(loop, [&] {
      for (std::size_t n = before; n < a.tx.size(); ++n)
        if (a.tx[n].first == target && a.tx[n].second == expected) return true;
      return false;
    });
    if (!arrived) {
      std::string seen;
      for (std::size_t n = before; n < a.tx.size(); ++n)
        seen += std::string(a.tx[n].first == target ? "" : "(other car) ") +
                std::string(anki::name(a.tx[n].second)) + " ";
      INFO("A's cars were sent: ", seen);
      CHECK_MESSAGE(false, "expected ", anki::name(expected));
    }
    return arrived;
  }
  // SDK mode stays the bridge's business: A's car was sent it once, when it connected to A.
  std::size_t sdkModesSent(int i) {
    std::size_t n = 0;
    for (const auto& [car, m] : a.tx)
      n += car == &aOf(i) && std::holds_alternative<anki::SdkMode>(m);
    return n;
  }
  bool allUp() const {
    return std::all_of(b.fleet.cars().begin(), b.fleet.cars().end(),
                       [](const AnkiCar* c) { return c->state().connected; });
  }
  bool allDown() const {
    return std::none_of(b.fleet.cars().begin(), b.fleet.cars().end(),
                        [](const AnkiCar* c) { return c->state().connected; });
  }
};

}  // namespace

TEST_CASE("mqtt remote: another host's cars join as connected cars that follow the real ones") {
  Pair p;
  std::vector<std::string> aNames, bNames;
  for (int i = 0; i < 2; ++i) {
    CAPTURE(i);
    AnkiCar& remote = p.b.car(i);
    CHECK(remote.state().connected);
    bNames.push_back(remote.identity().name);
    aNames.push_back(p.a.car(i).identity().name);
    AnkiCar& real = p.aOf(i);
    CHECK(remote.identity().model_id == real.identity().model_id);
    CHECK(remote.identity().identifier == real.identity().identifier);
    CHECK(remote.link().address() == "mqtt:" + p.a.bridge->carIdOf(real));
  }
  std::sort(aNames.begin(), aNames.end());
  std::sort(bNames.begin(), bNames.end());
  CHECK(aNames == bNames);
  CHECK(p.b.failed == std::nullopt);

  // B drives its car; A's car drives; A's frames come back as B's car's messages.
  int positions = 0;
  Subscription heard = p.b.car(0).messages.connect([&](const anki::Message& m) {
    positions += std::holds_alternative<anki::PositionUpdate>(m) ? 1 : 0;
  });
  REQUIRE(p.reaches(
      0, [](AnkiCar& c) { return c.setSpeed(600, 1000); }, anki::SetSpeed{600, 1000, false}));
  AnkiCar& real = p.aOf(0);
  CHECK(real.state().target_speed_mm_s == 600);
  REQUIRE(runUntil(p.loop, [&] { return positions >= 3 && p.b.car(0).state().speed_mm_s > 0; }));
  CHECK(p.a.simCar(0).truth().speed_mm_s > 0);
  REQUIRE(runUntil(p.loop, [&] {
    return p.b.car(0).state().piece >= 0 && p.b.car(0).state().piece == real.state().piece &&
           p.b.car(0).state().location == real.state().location;
  }));
  CHECK(p.b.car(0).state().frames_in > 0);
  CHECK(p.b.car(1).state().speed_mm_s == 0);
}

TEST_CASE("mqtt remote: every command on a remote car reaches the real car as the same message") {
  Pair p;
  auto check = [&](const std::function<AnkiCar::Sent(AnkiCar&)>& command,
                   const anki::Message& expected) { CHECK(p.reaches(0, command, expected)); };
  check([](AnkiCar& c) { return c.setSpeed(500); }, anki::SetSpeed{500, kDefaultAccel, false});
  // respect_limit has no key in the seed's speed intent: it travels as a frame
  check([](AnkiCar& c) { return c.setSpeed(550, 800, true); }, anki::SetSpeed{550, 800, true});
  check([](AnkiCar& c) { return c.changeLane(23, 250, 2000); },
        anki::ChangeLane{250, 2000, 23.0f, 0, 0});
  check([](AnkiCar& c) { return c.changeLane(-23.5); },
        anki::ChangeLane{kDefaultLaneSpeed, kDefaultLaneAccel, -23.5f, 0, 0});
  check([](AnkiCar& c) { return c.cancelLaneChange(); }, anki::CancelLaneChange{});
  check([](AnkiCar& c) { return c.setOffset(-68); }, anki::SetOffset{-68});
  CHECK(p.aOf(0).state().offset_mm == -68);  // the real car's belief is re-based too
  check([](AnkiCar& c) { return c.turn(anki::TurnType::UTurn, anki::TurnTrigger::Immediate); },
        anki::Turn{anki::TurnType::UTurn, anki::TurnTrigger::Immediate});
  check([](AnkiCar& c) { return c.lights(0x44); }, anki::SetLights{0x44});
  anki::LightsPattern pattern;
  pattern.channel_count = 1;
  pattern.channels[0] = anki::LightChannel{3, 2, 0, 14, 10};
  check([&](AnkiCar& c) { return c.lightsPattern(pattern); }, pattern);

  check([](AnkiCar& c) { return c.ping(); }, anki::PingRequest{});
  REQUIRE(runUntil(p.loop, [&] { return p.b.car(0).lastPingRtt().has_value(); }));
  CHECK(*p.b.car(0).lastPingRtt() > 0);

  check([](AnkiCar& c) { return c.requestBattery(); }, anki::BatteryRequest{});
  REQUIRE(runUntil(p.loop, [&] { return p.b.car(0).state().battery_mv > 0; }));
  CHECK(p.b.car(0).state().battery_mv == p.aOf(0).state().battery_mv);

  check([](AnkiCar& c) { return c.requestVersion(); }, anki::VersionRequest{});
  REQUIRE(runUntil(p.loop, [&] { return p.b.car(0).state().version > 0; }));
  CHECK(p.b.car(0).state().version == p.aOf(0).state().version);

  // SDK mode is accepted and nothing is sent (B's cars also asked for it when they connected).
  CHECK(p.b.car(0).sdkMode(true).ok());
  check([](AnkiCar& c) { return c.stop(); }, anki::SetSpeed{0, kStopAccel, false});
  CHECK(p.sdkModesSent(0) == 1);
  CHECK(p.sdkModesSent(1) == 1);
  // Nothing of the above went to the other car.
  for (const auto& [car, m] : p.a.tx)
    if (car == &p.aOf(1))
      CHECK((std::holds_alternative<anki::SdkMode>(m) ||
             std::holds_alternative<anki::VersionRequest>(m) ||
             std::holds_alternative<anki::BatteryRequest>(m)));
}

TEST_CASE("mqtt remote: the cars of a host that goes offline disconnect, and come back with it") {
  Pair p;
  SUBCASE("the bridge goes offline cleanly") {
    p.a.bridge->goOffline();
    REQUIRE(runUntil(p.loop, [&] { return p.allDown(); }));
    REQUIRE(p.b.downs.size() == 2);
    // not a structured binding: CAPTURE's lambda cannot capture one with clang 14 (the ASan
    // build, docs/testing.md)
    for (const auto& down : p.b.downs) {
      const std::string& name = down.first;
      const std::string& reason = down.second;
      CAPTURE(name);
      bool said = reason.find("offline") != std::string::npos;
      CHECK_MESSAGE(said, reason);
    }
    p.a.client->disconnect();
  }
  SUBCASE("the bridge's process dies: its will") {
    p.a.crash();
    REQUIRE(runUntil(p.loop, [&] { return p.allDown(); }));
    REQUIRE(p.b.downs.size() == 2);
    for (const auto& down : p.b.downs) {
      const std::string& name = down.first;
      const std::string& reason = down.second;
      CAPTURE(name);
      CHECK(reason == "host " + kHost + " is offline");
    }
  }
  CHECK(p.b.remote.onlineCount() == 0);
  CHECK(p.b.fleet.cars().size() == 2);
  // Commands to a car that is down are refused here, not sent.
  CHECK_FALSE(p.b.car(0).setSpeed(300).ok());

  p.a.startBridge();
  REQUIRE(runUntil(p.loop, [&] { return p.allUp(); }));
  CHECK(p.b.fleet.cars().size() == 2);  // the same cars, not new ones
  CHECK(p.b.remote.onlineCount() == 2);
  CHECK(p.reaches(
      1, [](AnkiCar& c) { return c.setSpeed(300); }, anki::SetSpeed{300, kDefaultAccel, false}));
}

TEST_CASE("mqtt remote: losing the broker disconnects the remote cars until it is back") {
  Pair p;
  int changes = p.b.changes;
  p.broker.stop();
  REQUIRE(runUntil(p.loop, [&] { return p.allDown(); }));
  CHECK(p.b.changes > changes);
  REQUIRE(p.b.downs.size() == 2);
  // Why depends on what reaches B first: its own loss of the broker, or A's will, which
  // mosquitto publishes as it shuts down.
  for (const auto& down : p.b.downs) {
    const std::string& reason = down.second;
    CAPTURE(reason);
    CHECK((reason.starts_with("MQTT: ") || reason == "host " + kHost + " is offline"));
  }
  CHECK(p.b.failed == std::nullopt);  // a lost broker is retried, not a failure
  p.broker.start();
  REQUIRE(runUntil(
      p.loop, [&] { return p.allUp(); }, 4s));
  CHECK(p.b.fleet.cars().size() == 2);
  CHECK(p.reaches(
      0, [](AnkiCar& c) { return c.setSpeed(400); }, anki::SetSpeed{400, kDefaultAccel, false}));
  REQUIRE(runUntil(p.loop, [&] { return p.b.car(0).state().speed_mm_s > 0; }));
}

// A client that publishes what it likes on the tree, and the warnings logged meanwhile.
struct Vandal {
  std::vector<std::string> warnings;
  MqttClient client;
  explicit Vandal(Pair& p) : client(p.loop, MqttOptions::fromUrl(p.broker.url())) {
    log::setSink([this](log::Level level, std::string_view line) {
      if (level == log::Level::Warn) warnings.emplace_back(line);
    });
    bool connected = false;
    client.onConnected = [&connected] { connected = true; };
    client.connect();
    REQUIRE(runUntil(p.loop, [&] { return connected; }));
    client.onConnected = nullptr;
  }
  ~Vandal() { log::setSink(nullptr); }
};

TEST_CASE("mqtt remote: malformed status and frames on the tree are ignored with a warning") {
  Pair p;
  Vandal v(p);
  MqttClient& vandal = v.client;
  const std::vector<std::string>& warnings = v.warnings;
  std::string id = p.a.bridge->carIdOf(p.aOf(0));
  std::string car = "Anki/Car/" + id;
  std::uint64_t malformed = p.b.car(0).state().malformed;

  REQUIRE(vandal.publish(car + "/S/CarStatus", "not json", 1));
  REQUIRE(vandal.publish(car + "/E/frame", R"({"timestamp":1,"value":"zz"})", 0));
  REQUIRE(vandal.publish(car + "/S/Information", "[]", 1));
  REQUIRE(vandal.publish("Anki/Car/stranger/S/Information", "{}", 1));
  REQUIRE(vandal.publish("Anki/Host/" + kHost + "/S/HostStatus", "yes", 1));
  REQUIRE(vandal.publish("Anki/Host/" + kHost + "/S/Cars", R"({"value":5})", 1));
  // well-formed hex, but no vehicle message: the car itself reports it as malformed
  REQUIRE(vandal.publish(car + "/E/frame", R"({"timestamp":1,"value":"05ff"})", 0));
  auto ignored = [&](const std::string& topic) {
    return std::any_of(warnings.begin(), warnings.end(), [&](const std::string& w) {
      return w.find("ignored " + topic) != std::string::npos;
    });
  };
  REQUIRE(runUntil(p.loop, [&] {
    return ignored(car + "/S/CarStatus") && ignored(car + "/E/frame") &&
           ignored(car + "/S/Information") && ignored("Anki/Car/stranger/S/Information") &&
           ignored("Anki/Host/" + kHost + "/S/HostStatus") &&
           ignored("Anki/Host/" + kHost + "/S/Cars") &&
           p.b.car(0).state().malformed == malformed + 1;
  }));

  // Nothing broke: the same two cars, online, driven as before.
  CHECK(p.b.fleet.cars().size() == 2);
  CHECK(p.allUp());
  CHECK(p.b.remote.onlineCount() == 2);
  CHECK(p.reaches(
      0, [](AnkiCar& c) { return c.setSpeed(450); }, anki::SetSpeed{450, kDefaultAccel, false}));
  REQUIRE(runUntil(p.loop, [&] { return p.b.car(0).state().speed_mm_s > 0; }));
}

TEST_CASE(
    "mqtt remote: hostile publications on every topic it reads are ignored, the cars follow") {
  Pair p;
  Vandal v(p);
  MqttClient& vandal = v.client;
  const std::vector<std::string>& warnings = v.warnings;
  const std::string car = "Anki/Car/" + p.a.bridge->carIdOf(p.aOf(0));
  const std::string host = "Anki/Host/" + kHost;
  const std::vector<std::string> read = {car + "/S/CarStatus",
                                         car + "/S/Information",
                                         car + "/E/frame",
                                         "Anki/Car/stranger/S/Information",
                                         "Anki/Car/stranger/S/CarStatus",
                                         host + "/S/HostStatus",
                                         host + "/S/Cars",
                                         host + "/S/IntentError",
                                         "Anki/Host/other/S/Cars"};
  // The reader is alive and a valid frame still updates the car: a battery report of its own.
  int millivolts = 3000;
  auto follows = [&] {
    ++millivolts;
    auto frame = anki::encode(anki::BatteryResponse{static_cast<std::uint16_t>(millivolts)});
    // E/frame is QoS 0: the broker may drop one behind a queue of large QoS 1 messages, so it is
    // sent again until it arrives
    for (int attempt = 0; attempt < 10; ++attempt) {
      REQUIRE(vandal.publish(car + "/E/frame",
                             R"({"timestamp":1,"value":")" + toHex(frame.span(), "") + R"("})", 0));
      if (runUntil(
              p.loop, [&] { return p.b.car(0).state().battery_mv == millivolts; }, 500ms))
        return true;
    }
    return false;
  };

  auto payloads = pitwall::testing::hostilePayloads();
  payloads.push_back({"empty", "", ""});
  payloads.push_back({"64 KB", pitwall::testing::paddedSpeedIntent(64 * 1024), ""});
  payloads.push_back({"64 deep", pitwall::testing::deepSpeedIntent(64), ""});
  // a valid hex frame of 32 KB: no vehicle message, the car counts it as malformed
  payloads.push_back({"a 32 KB frame", R"({"value":")" + std::string(64000, 'f') + R"("})", ""});
  auto start = p.loop.now();
  for (const auto& bad : payloads) {
    CAPTURE(bad.name);
    for (const auto& topic : read) REQUIRE(vandal.publish(topic, bad.payload, 1));
    CHECK(follows());
  }
  // The count of what was not logged comes with the next warning that is: one more bad
  // publication once a token is back (the flood may have ended while the bucket was empty).
  std::size_t before = warnings.size();
  pitwall::testing::runFor(p.loop, std::chrono::milliseconds(300));
  REQUIRE(vandal.publish(read[0], "not json", 1));
  CHECK(runUntil(p.loop, [&] { return warnings.size() > before; }));
  double seconds = toSeconds(p.loop.now() - start);
  CAPTURE(seconds);

  // Warnings name what was wrong in short lines, and a flood of junk is not a flood of them.
  CHECK(!warnings.empty());
  for (const auto& w : warnings) CHECK(w.size() < 1500);
  CHECK(warnings.size() <= 20 + 10 * seconds + 5);  // (+ the car's own about the 32 KB frame)
  CHECK(std::any_of(warnings.begin(), warnings.end(), [](const std::string& w) {
    return w.find("not logged before this one") != std::string::npos;
  }));

  // Nothing broke: the same two cars, online, driven as before.
  CHECK(p.b.fleet.cars().size() == 2);
  CHECK(p.allUp());
  CHECK(p.reaches(
      0, [](AnkiCar& c) { return c.setSpeed(450); }, anki::SetSpeed{450, kDefaultAccel, false}));
}

TEST_CASE("mqtt remote: ids a publisher invents are followed only up to a bound") {
  Pair p;
  Vandal v(p);
  std::string ids;
  for (int i = 0; i < 2000; ++i)
    ids += std::string(ids.empty() ? "" : ",") + "\"fake" + std::to_string(i) + "\"";
  REQUIRE(v.client.publish("Anki/Host/evil/S/Cars", R"({"timestamp":1,"value":[)" + ids + "]}", 1));
  REQUIRE(runUntil(p.loop, [&] {
    for (const auto& w : v.warnings)
      if (w.find("the tree names more than 1024 cars; no more are followed") != std::string::npos)
        return true;
    return false;
  }));
  // and the real cars still follow
  CHECK(p.reaches(
      0, [](AnkiCar& c) { return c.setSpeed(420); }, anki::SetSpeed{420, kDefaultAccel, false}));
}

TEST_CASE("mqtt remote: a car of the seed's controller: its S/Cars decides, E/Messages feed it") {
  // The controller's publications (hofdo/nodejsankisdk host.js, ReturnMsgHandler.js), by hand:
  // no E/frame, S/Cars a bare array or {}, no S/CarStatus when it drops a car.
  MosquittoBroker broker;
  Loop loop{ClockKind::Real};
  MqttClient controller(loop, MqttOptions::fromUrl(broker.url()));
  std::vector<std::pair<std::string, std::string>> intents;
  controller.onMessage = [&](std::string_view t, std::string_view p, bool) {
    intents.emplace_back(std::string(t), std::string(p));
  };
  controller.subscribe("Anki/Car/+/I/#", 1);
  controller.connect();
  REQUIRE(runUntil(loop, [&] { return controller.state() == MqttClient::State::Connected; }));
  const std::string car = "d205effe02cb", base = "Anki/Car/d205effe02cb/";
  auto retain = [&](const std::string& topic, const std::string& payload) {
    REQUIRE(controller.publish(topic, payload, 1, true));
  };
  retain("Anki/Host/host/S/HostStatus", R"({"value":true})");
  retain(base + "S/Information", R"({"address":"d2:05:ef:fe:02:cb","identifier":2018915346,)"
                                 R"("model":"Skull","modelId":9,"productId":61374})");
  // an S/CarStatus online left over from before: S/Cars, once it names the car, decides
  retain(base + "S/CarStatus", R"({"timestamp":1,"online":true,"charging":0,"onTrack":1})");
  retain("Anki/Host/host/S/Cars", R"(["d205effe02cb"])");

  RemoteHost b(loop, broker);
  REQUIRE(runUntil(loop, [&] { return b.synced && b.remote.onlineCount() == 1; }));
  AnkiCar& remote = b.car(0);
  CHECK(remote.identity().model_id == 9);

  // its position updates, rebuilt from the controller's whole-message events
  REQUIRE(controller.publish(
      base + "E/Messages/ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE",
      R"({"message_id":39,"offset":-23.5,"speed":512,"flag":71,"pieceId":36,"pieceLocation":5,)"
      R"("isReverse":false,"last_des_speed":500,"last_rec_lane_change_cmd":0,)"
      R"("last_exe_lane_change_cmd":0,"last_des_lane_change_speed":0})",
      0, false));
  REQUIRE(runUntil(loop, [&] { return remote.state().piece == 36; }));
  CHECK(remote.state().speed_mm_s == 512);
  CHECK(remote.state().offset_mm == -23.5);
  REQUIRE(controller.publish(base + "E/Messages/ANKI_VEHICLE_MSG_V2C_BATTERY_LEVEL_RESPONSE",
                             R"({"message_id":27,"value":3950})", 0, false));
  REQUIRE(runUntil(loop, [&] { return remote.state().battery_mv == 3950; }));

  // commands go as the controller's intents; one it has no intent for is refused, unsent
  intents.clear();
  REQUIRE(remote.setSpeed(600, 2000).ok());
  REQUIRE(runUntil(loop, [&] { return !intents.empty(); }));
  CHECK(intents.back() ==
        std::pair<std::string, std::string>{base + "I", R"({"speed":600,"acceleration":2000})"});
  auto lights = remote.lights(0x44);
  REQUIRE_FALSE(lights.ok());
  CHECK(lights.error() ==
        "car 1 (skull): set-lights was not sent: car d205effe02cb is bridged by the seed's "
        "controller (its S/Information names no pitwall bridge), which has no intent for "
        "set-lights; it takes speed, lane, turn, battery, version and ping");

  // connecting false: S/Cars {} and a blank S/Information; the stale CarStatus keeps nothing up
  retain("Anki/Host/host/S/Cars", "{}");
  retain(base + "S/Information",
         R"({"address":"","identifier":"","model":"","modelId":"","productId":""})");
  REQUIRE(runUntil(loop, [&] { return !remote.state().connected; }));
  CHECK(b.downs.back().second == "its bridge reports it offline");
  // and back
  retain(base + "S/Information", R"({"address":"d2:05:ef:fe:02:cb","identifier":2018915346,)"
                                 R"("model":"Skull","modelId":9,"productId":61374})");
  retain("Anki/Host/host/S/Cars", R"(["d205effe02cb"])");
  REQUIRE(runUntil(loop, [&] { return remote.state().connected; }));
  CHECK(b.fleet.cars().size() == 1);  // the same car, not a second one
}
