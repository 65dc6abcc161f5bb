// MqttBridge against a real mosquitto broker (tests/support/mosquitto_broker.hpp): two simulated
// cars on the oval, driven in real time on the one real-clock loop, published under the seed's
// topic tree; intents sent by an observer client that also records everything under Anki/#.
#include "tests/support/sim_cars.hpp"
#include "tests/unit/mqtt/bridge_fixture.hpp"

#include <doctest/doctest.h>

using namespace pitwall;
using namespace pitwall::testing::bridge;
using namespace std::chrono_literals;
using pitwall::testing::hostilePayloads;
using pitwall::testing::MosquittoBroker;
using pitwall::testing::runFor;
using pitwall::testing::runUntil;

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
  CHECK(late.json(kCars).get<std::vector<std::string>>() == sorted({h.id(0), h.id(1)}));
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
      return o.json(kCars).empty() && o.json(h.carTopic(0, "S/CarStatus"))["online"] == false &&
             o.json(h.carTopic(1, "S/CarStatus"))["online"] == false;
    }));
    CHECK(h.sent<anki::Disconnect>(0).size() == 1);
    CHECK(h.sent<anki::Disconnect>(1).size() == 1);
    CHECK_FALSE(h.simCar(0).truth().connected);
    o.send(kHostIntent + "/connection", R"({"connecting":true})");
    REQUIRE(runUntil(loop, [&] { return h.fleet.connectedCount() == 2; }));
    REQUIRE(runUntil(loop, [&] {
      return o.json(kCars).size() == 2 && o.json(h.carTopic(0, "S/CarStatus"))["online"] == true &&
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
      {kHostIntent, R"({"type":"lane","offset":-70.5})", false, "out of range -70..70 mm"},
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
  // The bridge republishes some 20 retained messages at QoS 1 and its client has at most 20 in
  // flight: the last ones may still be on their way when the late subscriber comes, and reach it
  // live. Await them (the car list comes last), not a round trip of the subscriber's own.
  REQUIRE(runUntil(loop, [&] {
    return late.has(kCars) && late.has(h.carTopic(0, "S/Speed/Desired")) &&
           late.has(h.carTopic(1, "S/Speed/Desired"));
  }));
  CHECK(late.json(kHostStatus) == Json{{"value", true}});
  CHECK(late.json(kCars).get<std::vector<std::string>>() == sorted({h.id(0), h.id(1)}));
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
    for (int i = 0; i < 2; ++i)
      testing::addSimulatedCar(childLoop, fleet, world, sim::gridSpec(world.track(), i));
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
    return o.json(kHostStatus) == Json{{"value", true}} && cars.is_array() && cars.size() == 2;
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
  CHECK(o.json(kCars).empty());
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
  CHECK(late.json(kCars).empty());
  CHECK(late.json(h.carTopic(0, "S/CarStatus"))["online"] == false);
}

TEST_CASE_FIXTURE(Bridged, "mqtt bridge: a client of the seed's controller drives it unchanged") {
  const std::string one = h.carTopic(0, "I");
  SUBCASE("key-named commands to one car, below its I, and to every car on Anki/Car/I") {
    o.send(one, R"({"speed":600,"acceleration":5000})");
    REQUIRE(runUntil(loop, [&] { return !h.sent<anki::SetSpeed>(0).empty(); }));
    CHECK(h.sent<anki::SetSpeed>(0).back() == anki::SetSpeed{600, 5000, false});
    CHECK(h.sent<anki::SetSpeed>(1).empty());
    o.send(one + "/lane", R"({"lane":-23})");
    REQUIRE(runUntil(loop, [&] { return !h.sent<anki::ChangeLane>(0).empty(); }));
    CHECK(h.sent<anki::ChangeLane>(0).back().offset_mm == -23.0f);
    o.send(one, R"({"turn":{"type":3,"time":0}})");
    REQUIRE(runUntil(loop, [&] { return !h.sent<anki::Turn>(0).empty(); }));
    CHECK(h.sent<anki::Turn>(0).back() ==
          anki::Turn{anki::TurnType::UTurn, anki::TurnTrigger::Immediate});
    o.send(one, R"({"ping":true})");
    REQUIRE(runUntil(loop, [&] { return o.has(h.carTopic(0, "S/PingResp")); }));
    CHECK(o.json(h.carTopic(0, "S/PingResp"))["rtt_ms"].is_number());
    // the two are published one after the other: the second may arrive a moment later
    CHECK(runUntil(loop, [&] {
      return o.has(h.carTopic(0, "E/Messages/ANKI_VEHICLE_MSG_V2C_PING_RESPONSE"));
    }));
    o.send("Anki/Car/I", R"({"speed":0,"acceleration":12500})");
    REQUIRE(runUntil(loop, [&] {
      return h.sent<anki::SetSpeed>(0).size() == 2 && h.sent<anki::SetSpeed>(1).size() == 1;
    }));
    CHECK(h.sent<anki::SetSpeed>(1).back() == anki::SetSpeed{0, 12500, false});
  }
  SUBCASE("connecting false and true on the host's I: E/CarDisconnected, E/CarConnected, S/Cars") {
    const std::string disconnected = "Anki/Host/" + kHost + "/E/CarDisconnected";
    const std::string connected = "Anki/Host/" + kHost + "/E/CarConnected";
    o.send(kHostIntent, R"({"connecting":false})");
    REQUIRE(runUntil(loop, [&] { return o.count(disconnected) == 2; }));
    std::vector<std::string> gone;
    for (auto* m : o.on(disconnected)) gone.push_back(Json::parse(m->payload)["Car"]);
    CHECK(sorted(gone) == sorted({h.id(0), h.id(1)}));
    REQUIRE(runUntil(loop, [&] { return o.json(kCars) == Json::array(); }));
    o.send(kHostIntent, R"({"connecting":true})");
    REQUIRE(runUntil(loop, [&] { return o.count(connected) == 2; }));
    REQUIRE(runUntil(loop, [&] { return o.json(kCars).size() == 2; }));
    CHECK_FALSE(o.last(connected)->retained);
  }
  SUBCASE("connecting true with every car connected still answers with S/Cars, live") {
    // The track editor skips a retained S/Cars: it waits for the one its intent brings.
    auto before = o.count(kCars);
    o.send(kHostIntent, R"({"connecting":true})");
    REQUIRE(runUntil(loop, [&] { return o.count(kCars) == before + 1; }));
    CHECK_FALSE(o.last(kCars)->retained);  // delivered live: the broker clears the flag
    CHECK(o.json(kCars).get<std::vector<std::string>>() == sorted({h.id(0), h.id(1)}));
  }
  SUBCASE("cars and car_status publish the list and every car's information again") {
    auto cars = o.count(kCars);
    o.send(kHostIntent + "/anything", R"({"cars":true})");
    REQUIRE(runUntil(loop, [&] { return o.count(kCars) == cars + 1; }));
    auto info = o.count(h.carTopic(1, "S/Information"));
    o.send(kHostIntent, R"({"car_status":true})");
    REQUIRE(runUntil(loop, [&] { return o.count(h.carTopic(1, "S/Information")) == info + 1; }));
    CHECK(o.json(h.carTopic(1, "S/Information"))["modelId"] == h.car(1).identity().model_id);
  }
  CHECK_FALSE(o.has(kIntentError));
  CHECK(h.bridge->stats().rejected == 0);
}

TEST_CASE_FIXTURE(Bridged, "mqtt bridge: the whole-message events carry what the dashboards read") {
  // The seed's controller's digital twin reads E/Messages/… only: speed, offset, pieceId.
  REQUIRE(h.car(0).setSpeed(600).ok());
  const std::string topic =
      h.carTopic(0, "E/Messages/ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE");
  REQUIRE(runUntil(loop, [&] { return o.has(topic) && o.json(topic)["speed"].get<int>() > 0; }));
  auto j = o.json(topic);
  CHECK(j["message_id"] == 39);
  CHECK(j["pieceId"].is_number_integer());
  CHECK(j["offset"].is_number());
  CHECK(j["isReverse"].is_boolean());
  CHECK_FALSE(o.last(topic)->retained);
}
