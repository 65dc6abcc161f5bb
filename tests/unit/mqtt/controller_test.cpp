// The seed's controller's forms against an adversary (cases written by an adversarial review;
// each once reproduced a defect or held against one): hostile values in the controller's forms
// and in E/Messages, floods of host intents, retained intents on the controller's topics, and
// remote cars moving between a pitwall bridge and the controller, fed by a plain publisher that
// plays both. A payload of many distinct keys costs time linear in its size: see
// tests/bench/mqtt_bench.cpp BM_IntentManyKeys.
#include <doctest/doctest.h>

#include <algorithm>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/mqtt/remote.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "tests/unit/mqtt/bridge_fixture.hpp"

using namespace pitwall;
using namespace std::chrono_literals;
using pitwall::testing::MosquittoBroker;
using pitwall::testing::runUntil;

namespace {

// ---- parser ----

const std::vector<std::string> kReviewCars{"e85a0f112233"};

Result<topics::Intent, topics::IntentError> parseCar(const std::string& payload) {
  return topics::parseIntent("pit1", "Anki/Car/e85a0f112233/I", payload, kReviewCars);
}

// ---- RemoteCars against a hand-made tree ----

const std::string kId = "d205effe02cb";
const std::string kBase = "Anki/Car/" + kId + "/";
const std::string kControllerInfo =
    R"({"address":"d2:05:ef:fe:02:cb","identifier":2018915346,"model":"Skull","modelId":9,)"
    R"("productId":61374})";
// What a pitwall bridge on host pitA publishes for a car (topics::carJoined, as MqttBridge calls
// it): with "bridge":"pitwall" and "host":"pitA", which the controller never sends.
std::string pitwallInfo(const std::string& id, const std::string& host = "pitA") {
  topics::CarInfo info;
  info.id = id;
  info.address = "D2:05:EF:FE:02:CB";
  info.identifier = 305419896;
  info.model_id = 9;
  info.name = "skull";
  info.pitwall = true;
  info.host = host;
  return topics::carJoined(info, CarState{}, 1).at(0).payload;
}
const std::string kPitwallInfo = pitwallInfo(kId);

struct Publisher {
  MqttClient client;
  std::vector<std::pair<std::string, std::string>> intents;  // what reached Anki/Car/+/I/#
  Publisher(Loop& loop, const MosquittoBroker& broker)
      : client(loop, MqttOptions::fromUrl(broker.url())) {
    client.onMessage = [this](std::string_view t, std::string_view p, bool) {
      intents.emplace_back(std::string(t), std::string(p));
    };
    client.subscribe("Anki/Car/+/I/#", 1);
    client.connect();
    REQUIRE(runUntil(loop, [&] { return client.state() == MqttClient::State::Connected; }));
  }
  void retain(const std::string& topic, const std::string& payload) {
    REQUIRE(client.publish(topic, payload, 1, true));
  }
  void event(const std::string& topic, const std::string& payload) {
    REQUIRE(client.publish(topic, payload, 0, false));
  }
  // The retained tree of a pitwall bridge pitA that has the car connected.
  void pitwallHasIt() {
    retain("Anki/Host/pitA/S/HostStatus", R"({"value":true})");
    retain(kBase + "S/Information", kPitwallInfo);
    retain(kBase + "S/CarStatus", R"({"timestamp":1,"online":true,"charging":false,)"
                                  R"("onTrack":true})");
    retain("Anki/Host/pitA/S/Cars", "[\"" + kId + "\"]");
  }
  // The retained tree of the seed's controller (host "host") that has the car connected.
  void controllerHasIt() {
    retain("Anki/Host/host/S/HostStatus", R"({"value":true})");
    retain(kBase + "S/Information", kControllerInfo);
    retain("Anki/Host/host/S/Cars", "[\"" + kId + "\"]");
  }
};

struct Remote {
  Fleet fleet;
  MqttClient client;
  RemoteCars remote;
  bool synced = false;
  std::vector<std::string> downs;
  Subscription watch;
  Remote(Loop& loop, const MosquittoBroker& broker)
      : fleet(loop), client(loop, MqttOptions::fromUrl(broker.url())), remote(loop, fleet, client) {
    watch = fleet.connectionChanged.connect([this](AnkiCar&, bool up, const std::string& reason) {
      if (!up) downs.push_back(reason);
    });
    remote.start([this] { synced = true; }, [](const std::string&) {});
  }
};

std::string frameEvent(const anki::Message& m) {
  auto frame = anki::encode(m);
  return R"({"timestamp":1,"value":")" + toHex(frame.span(), "") + R"("})";
}

// A broker, a publisher playing the bridges, and host B with remote cars only.
struct Tree {
  MosquittoBroker broker;
  Loop loop{ClockKind::Real};
  Publisher pub{loop, broker};
  std::unique_ptr<Remote> b;
  // B starts and its one remote car, whatever pub made of it, comes online.
  AnkiCar& remoteCar() {
    b = std::make_unique<Remote>(loop, broker);
    REQUIRE(runUntil(loop, [&] { return b->synced && b->remote.onlineCount() == 1; }));
    return *b->fleet.cars().at(0);
  }
};

}  // namespace

// ============================== parser: what held ==============================

TEST_CASE(
    "mqtt controller: hostile numbers in the controller's forms are refused or read exactly") {
  using topics::SpeedIntent;
  auto speedOf = [](const std::string& payload) -> std::optional<int> {
    auto r = parseCar(payload);
    if (!r) return std::nullopt;
    auto* s = std::get_if<SpeedIntent>(&r->action);
    return s ? std::optional<int>(s->speed_mm_s) : std::nullopt;
  };
  CHECK(speedOf(R"({"speed":"-0"})") == 0);
  CHECK(speedOf(R"({"speed":-0.0})") == 0);
  CHECK(speedOf(R"({"speed":" 600 "})") == 600);
  CHECK(speedOf(R"({"speed":"1e3"})") == 1000);
  CHECK_FALSE(speedOf(R"({"speed":"1e999"})"));
  CHECK_FALSE(speedOf(R"({"speed":"nan"})"));
  CHECK_FALSE(speedOf(R"({"speed":"-nan"})"));
  CHECK_FALSE(speedOf(R"({"speed":"inf"})"));
  CHECK_FALSE(speedOf(R"({"speed":"infinity"})"));
  CHECK_FALSE(speedOf(R"({"speed":"0x10"})"));
  CHECK_FALSE(speedOf(R"({"speed":1e308})"));
  CHECK_FALSE(speedOf(R"({"speed":18446744073709551615})"));
  CHECK_FALSE(speedOf(R"({"speed":-9223372036854775808})"));
  CHECK_FALSE(speedOf(R"({"speed":true})"));
  CHECK_FALSE(speedOf(R"({"speed":[600]})"));
  CHECK_FALSE(speedOf(R"({"speed":{"v":600}})"));
  CHECK_FALSE(speedOf(R"({"speed":-0.6})"));
  CHECK(speedOf(R"({"speed":1500.4})") == 1500);
  CHECK_FALSE(speedOf(R"({"speed":1500.5})"));
  CHECK_FALSE(speedOf(R"({"speed":600,"acceleration":"nan"})"));
  CHECK_FALSE(speedOf(R"({"speed":600,"acceleration":25000.6})"));
  // duplicate keys: the last one wins (nlohmann), never two commands
  CHECK(speedOf(R"({"speed":600,"speed":0})") == 0);
  // invalid UTF-8 in a key is a parse error, quoted escaped
  auto utf8 = parseCar("{\"\xff\":1}");
  REQUIRE_FALSE(utf8);
  MESSAGE(utf8.error().message);
  CHECK(utf8.error().message.find("\\xff") != std::string::npos);
  // deep nesting inside turn stops at the depth limit
  std::string deep = R"({"turn":{"type":)" + std::string(200, '[') + std::string(200, ']') + "}}";
  auto d = parseCar(deep);
  REQUIRE_FALSE(d);
  CHECK(d.error().message.find("more than 64 deep") != std::string::npos);
  // lane: strings and bounds
  auto lane = [](const std::string& payload) { return parseCar(payload); };
  CHECK_FALSE(lane(R"({"lane":"70.0001"})"));
  CHECK_FALSE(lane(R"({"lane":"nan"})"));
  CHECK(lane(R"({"lane":"-70"})"));
}

TEST_CASE("mqtt controller: E/Messages with out-of-range values are named errors") {
  const std::string pos = "ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE";
  for (const char* payload :
       {R"({"offset":1e39})", R"({"speed":70000})", R"({"speed":-1})", R"({"flag":1.5})",
        R"({"pieceId":256})", R"({"offset":"nan"})", R"({"offset":null})", R"({"speed":1e400})"}) {
    CAPTURE(payload);
    auto r = topics::readMessageEvent(pos, payload);
    REQUIRE_FALSE(r);
    MESSAGE(payload, " -> ", r.error());
  }
}

// ============================== bridge ==============================

namespace {
using namespace pitwall::testing::bridge;
}

TEST_CASE_FIXTURE(
    Bridged, "mqtt controller: a flood of {\"cars\":true} does not starve a connection intent") {
  // One client asks for the car list over and over (a dashboard's refresh loop, or a vandal);
  // another then disconnects every car. The disconnect must not be dropped by the republish flood.
  auto before = o.count(kCars);
  for (int i = 0; i < 300; ++i) o.send(kHostIntent, R"({"cars":true})");
  o.send(kHostIntent, R"({"connecting":false})");
  REQUIRE(o.roundTrip(loop));
  bool disconnected = runUntil(loop, [&] { return h.fleet.connectedCount() == 0; });
  MESSAGE("S/Cars republished ", o.count(kCars) - before, " times for 300 cars intents; throttled ",
          h.bridge->stats().throttled);
  if (auto* e = o.last(kIntentError)) MESSAGE("last IntentError: ", e->payload);
  CHECK_MESSAGE(disconnected, "{\"connecting\":false} was dropped behind the cars intents");
}

TEST_CASE_FIXTURE(Bridged,
                  "mqtt controller: an intent below another online host's car's I is left to it") {
  o.send("Anki/Host/other/S/HostStatus", R"({"value":true})", true);
  o.send("Anki/Host/other/S/Cars", R"(["xyz"])", true);
  REQUIRE(o.roundTrip(loop));
  o.send("Anki/Car/xyz/I/speed", R"({"speed":600})");
  o.send("Anki/Car/nobody/I/speed", R"({"speed":600})");  // the marker: nobody's car
  REQUIRE(runUntil(loop, [&] { return o.count(kIntentError) >= 1; }));
  REQUIRE(o.roundTrip(loop));
  CHECK(o.count(kIntentError) == 1);
  CHECK(o.json(kIntentError)["topic"] == "Anki/Car/nobody/I/speed");
  CHECK(h.sent<anki::SetSpeed>(0).empty());
}

TEST_CASE("mqtt controller: retained intents on the controller's new topics are refused at start") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  Observer o(loop, broker);
  REQUIRE(runUntil(loop, [&] { return o.connects == 1; }));
  o.send("Anki/Car/I", R"({"speed":600})", true);
  o.send(kHostIntent + "/sub", R"({"speed":700})", true);
  o.send(kHostIntent + "/sub2", R"({"connecting":false})", true);
  REQUIRE(o.roundTrip(loop));
  Host h(loop, broker);
  REQUIRE(runUntil(loop, [&] { return o.count(kIntentError) >= 3; }));
  CHECK(h.sent<anki::SetSpeed>(0).empty());
  CHECK(h.fleet.connectedCount() == 2);
  for (auto* m : o.on(kIntentError))
    CHECK(Json::parse(m->payload)["error"].get<std::string>().find("retained") !=
          std::string::npos);
}

// ============================== remote cars ==============================

TEST_CASE(
    "mqtt controller: a car its host's S/Cars lists is up although an older S/CarStatus said "
    "offline") {
  // docs/mqtt.md: "once a host's list named the car, the list decides". A pitwall bridge that
  // said goodbye left S/CarStatus online:false retained; the seed's controller then connected
  // the car (it publishes no S/CarStatus until the car sends a status message).
  MosquittoBroker broker;
  Loop loop{ClockKind::Real};
  Publisher pub(loop, broker);
  pub.retain(kBase + "S/CarStatus", R"({"timestamp":1,"online":false,"charging":false,)"
                                    R"("onTrack":false})");
  pub.controllerHasIt();
  Remote b(loop, broker);
  REQUIRE(runUntil(loop, [&] { return b.synced; }));
  bool up = runUntil(loop, [&] { return b.remote.onlineCount() == 1; });
  CHECK_MESSAGE(up, "listed by host's S/Cars, yet not online (a stale S/CarStatus keeps it down)");
}

TEST_CASE_FIXTURE(
    Tree,
    "mqtt controller: a car that moves from a pitwall bridge to the controller keeps its events") {
  // a pitwall bridge pitA has the car
  pub.pitwallHasIt();
  AnkiCar& car = remoteCar();
  pub.event(kBase + "E/frame", frameEvent(anki::PositionUpdate{1, 10, 0, 300, 0x47}));
  REQUIRE(runUntil(loop, [&] { return car.state().piece == 10; }));

  // pitA lets the car go; the seed's controller connects it (and the car reports its status)
  pub.retain("Anki/Host/pitA/S/Cars", "[]");
  REQUIRE(runUntil(loop, [&] { return !car.state().connected; }));
  pub.retain("Anki/Host/host/S/HostStatus", R"({"value":true})");
  pub.retain(kBase + "S/Information", kControllerInfo);
  pub.retain(kBase + "S/CarStatus", R"({"timestamp":2,"online":true,"charging":0,"onTrack":1})");
  pub.retain("Anki/Host/host/S/Cars", "[\"" + kId + "\"]");
  REQUIRE(runUntil(loop, [&] { return car.state().connected; }));
  CHECK(b->fleet.cars().size() == 1);

  pub.event(kBase + "E/Messages/ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE",
            R"({"message_id":39,"offset":-23.5,"speed":512,"flag":71,"pieceId":36,)"
            R"("pieceLocation":5,"isReverse":false,"last_des_speed":500,)"
            R"("last_rec_lane_change_cmd":0,"last_exe_lane_change_cmd":0,)"
            R"("last_des_lane_change_speed":0})");
  bool fed = runUntil(loop, [&] { return car.state().piece == 36; });
  CHECK_MESSAGE(fed,
                "the controller's E/Messages were ignored: one E/frame seen earlier, from "
                "another bridge, made the car deaf to them for good");
}

TEST_CASE_FIXTURE(
    Tree,
    "mqtt controller: a car that moves from the controller to a pitwall bridge takes lights") {
  pub.controllerHasIt();
  AnkiCar& car = remoteCar();
  pub.event(kBase + "E/Messages/ANKI_VEHICLE_MSG_V2C_BATTERY_LEVEL_RESPONSE",
            R"({"message_id":27,"value":3950})");
  REQUIRE(runUntil(loop, [&] { return car.state().battery_mv == 3950; }));

  // the controller drops it ({} and a blank S/Information); pitwall bridge pitA connects it
  pub.retain("Anki/Host/host/S/Cars", "{}");
  pub.retain(kBase + "S/Information",
             R"({"address":"","identifier":"","model":"","modelId":"","productId":""})");
  REQUIRE(runUntil(loop, [&] { return !car.state().connected; }));
  pub.pitwallHasIt();
  REQUIRE(runUntil(loop, [&] { return car.state().connected; }));
  pub.event(kBase + "E/frame", frameEvent(anki::BatteryResponse{3999}));
  REQUIRE(runUntil(loop, [&] { return car.state().battery_mv == 3999; }));  // E/frame read

  pub.intents.clear();
  auto lights = car.lights(0x44);
  if (!lights) MESSAGE("lights refused: ", lights.error());
  CHECK_MESSAGE(lights.ok(),
                "a pitwall bridge's car (its S/Information says so) is still treated as the "
                "controller's: lights refused");
}

TEST_CASE_FIXTURE(
    Tree,
    "mqtt controller: an E/Messages before the first E/frame does not make a pitwall car the "
    "controller's") {
  pub.pitwallHasIt();
  AnkiCar& car = remoteCar();
  // one stray (or lost-E/frame) whole-message event, then the bridge's E/frame stream
  pub.event(kBase + "E/Messages/ANKI_VEHICLE_MSG_V2C_PING_RESPONSE", R"({"message_id":23})");
  pub.event(kBase + "E/frame", frameEvent(anki::BatteryResponse{3999}));
  REQUIRE(runUntil(loop, [&] { return car.state().battery_mv == 3999; }));
  auto lights = car.lights(0x44);
  if (!lights) MESSAGE("lights refused: ", lights.error());
  CHECK(lights.ok());
}

// A position update on piece 36 as the seed's controller's whole-message event.
const std::string kPositionMessage =
    R"({"message_id":39,"offset":-23.5,"speed":512,"flag":71,"pieceId":36,"pieceLocation":5,)"
    R"("isReverse":false,"last_des_speed":500,"last_rec_lane_change_cmd":0,)"
    R"("last_exe_lane_change_cmd":0,"last_des_lane_change_speed":0})";
const std::string kPositionTopic = "E/Messages/ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE";

TEST_CASE_FIXTURE(
    Tree,
    "mqtt remote: a pitwall bridge's car whose first E/frame is withheld takes every command as "
    "the same message") {
  // Issue 33: the remote reader took a pitwall bridge's car for the seed's controller's until its
  // first E/frame came, so an E/Messages that came first (its E/frame lost, or overtaken by a
  // status message at the broker) made every command the controller has no intent for refused —
  // and the message read twice. The car's S/Information says what bridges it now.
  const std::string other = "pitA-sim-00000002", otherBase = "Anki/Car/" + other + "/";
  pub.retain("Anki/Host/pitA/S/HostStatus", R"({"value":true})");
  pub.retain(kBase + "S/Information", kPitwallInfo);
  pub.retain(otherBase + "S/Information", pitwallInfo(other));
  pub.retain("Anki/Host/pitA/S/Cars", "[\"" + kId + "\",\"" + other + "\"]");
  b = std::make_unique<Remote>(loop, broker);
  REQUIRE(runUntil(loop, [&] { return b->synced && b->remote.onlineCount() == 2; }));
  auto byId = [&](const std::string& id) {
    AnkiCar* found = nullptr;
    for (auto* c : b->fleet.cars())
      if (c->link().address() == "mqtt:" + id) found = c;
    REQUIRE(found);
    return found;
  };
  AnkiCar& car = *byId(kId);
  AnkiCar& marker = *byId(other);

  // The whole-message event of a position update without its E/frame, then the other car's
  // E/frame: both QoS 0 from one publisher, so the second marks that the first was handled.
  pub.event(kBase + kPositionTopic, kPositionMessage);
  pub.event(otherBase + "E/frame", frameEvent(anki::BatteryResponse{3999}));
  REQUIRE(runUntil(loop, [&] { return marker.state().battery_mv == 3999; }));
  CHECK_MESSAGE(car.state().piece != 36,
                "a pitwall bridge's E/Messages were read: its E/frame carries the same message, "
                "so every event would come twice");

  // Commands the controller has no intent for travel as pitwall's message intent, unchanged.
  const std::vector<anki::Message> sent{anki::SetSpeed{550, 800, true}, anki::SetLights{0x44},
                                        anki::SetOffset{-68}};
  for (const auto& r : {car.setSpeed(550, 800, true), car.lights(0x44), car.setOffset(-68)}) {
    if (!r.ok()) MESSAGE("refused: ", r.error());
    CHECK(r.ok());
  }
  auto messageIntents = [&] {
    std::vector<std::pair<std::string, std::string>> out;
    for (const auto& i : pub.intents)
      if (i.second.find(R"("type":"message")") != std::string::npos) out.push_back(i);
    return out;
  };
  REQUIRE(runUntil(loop, [&] { return messageIntents().size() == sent.size(); }));
  for (std::size_t i = 0; i < sent.size(); ++i) {
    CAPTURE(i);
    CHECK(messageIntents()[i] ==
          std::pair<std::string, std::string>{kBase + "I", *topics::intentPayload(sent[i])});
  }
}

TEST_CASE_FIXTURE(Tree,
                  "mqtt remote: a car of the seed's controller is known as one before any event") {
  pub.controllerHasIt();
  AnkiCar& car = remoteCar();
  auto lights = car.lights(0x44);  // no E/Messages has come yet: its S/Information says enough
  REQUIRE_FALSE(lights.ok());
  CHECK(lights.error().find("bridged by the seed's controller (its S/Information names no pitwall "
                            "bridge), which has no intent for set-lights") != std::string::npos);
  pub.intents.clear();
  REQUIRE(car.setSpeed(600, 2000).ok());  // its own intents go as they are
  // (an intent of the connection's, still in flight through the broker on a loaded machine, may
  // arrive after the clear: wait for this one, not for any)
  const std::pair<std::string, std::string> speed{kBase + "I",
                                                  R"({"speed":600,"acceleration":2000})"};
  CHECK(runUntil(loop, [&] {
    return std::find(pub.intents.begin(), pub.intents.end(), speed) != pub.intents.end();
  }));
}

TEST_CASE_FIXTURE(Tree,
                  "mqtt remote: a car another host lists is down until that host's S/Information "
                  "comes, then of its kind") {
  pub.pitwallHasIt();
  AnkiCar& car = remoteCar();
  // The seed's controller (host "host") lists the car while its S/Information is still pitA's:
  // pitA's word about the car is not the controller's.
  pub.retain("Anki/Host/host/S/HostStatus", R"({"value":true})");
  pub.retain("Anki/Host/host/S/Cars", "[\"" + kId + "\"]");
  REQUIRE(runUntil(loop, [&] { return !car.state().connected; }));
  CHECK(b->downs.back() ==
        "host host has it, but its information is host pitA's (waiting for "
        "host's)");
  CHECK_FALSE(car.lights(0x44).ok());
  pub.retain(kBase + "S/Information", kControllerInfo);
  REQUIRE(runUntil(loop, [&] { return car.state().connected; }));
  // the controller's car now: its E/Messages are read, lights refused
  pub.event(kBase + kPositionTopic, kPositionMessage);
  REQUIRE(runUntil(loop, [&] { return car.state().piece == 36; }));
  auto lights = car.lights(0x44);
  REQUIRE_FALSE(lights.ok());
  CHECK(lights.error().find("bridged by the seed's controller") != std::string::npos);
  CHECK(b->fleet.cars().size() == 1);
}

TEST_CASE_FIXTURE(Tree, "mqtt controller: S/Cars flipped hundreds of times never grows the fleet") {
  pub.controllerHasIt();
  AnkiCar& car = remoteCar();
  log::setSink([](log::Level, std::string_view) {});
  // 600 retained publications: fewer than the broker queues for a client (1000), so none is
  // dropped, the HostStatus behind them included. What counts is where the car ends up, and
  // that it stays one car.
  for (int i = 0; i < 600; ++i)
    pub.retain("Anki/Host/host/S/Cars", i % 2 ? "[\"" + kId + "\"]" : "[]");  // ends listed
  // Then the host goes offline: that reason comes only after the whole flood was read.
  pub.retain("Anki/Host/host/S/HostStatus", R"({"value":false})");
  // a limit, not a measure: each flip brings the car down or up, slowly under ASan
  REQUIRE(runUntil(
      loop, [&] { return !b->downs.empty() && b->downs.back() == "host host is offline"; },
      std::chrono::seconds(60)));
  pub.retain("Anki/Host/host/S/HostStatus", R"({"value":true})");
  REQUIRE(runUntil(loop, [&] { return car.state().connected; }));
  log::setSink(nullptr);
  CHECK_FALSE(b->downs.empty());
  CHECK(b->fleet.cars().size() == 1);
  CHECK(b->remote.onlineCount() == 1);
}
