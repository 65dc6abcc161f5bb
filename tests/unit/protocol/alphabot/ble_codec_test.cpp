// The Alphabot BLE codec against golden bytes (alphabot.md §2, §3; docs/robots.md):
// every characteristic both ways, the 9-bit degree split, the request/answer bit, the limits of
// the one-byte fields, every decode error, and a brute-force check that decoding is total.
#include "engine/protocol/alphabot/ble_codec.hpp"

#include <doctest/doctest.h>

#include <random>
#include <string>
#include <vector>

using namespace pitwall::alphabot;
using namespace pitwall::alphabot::ble;

namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes bytes(std::string_view hex) {
  Bytes out;
  for (std::size_t i = 0; i < hex.size(); i += 3)
    out.push_back(static_cast<std::uint8_t>(std::stoi(std::string(hex.substr(i, 2)), nullptr, 16)));
  return out;
}

BleValue ok(const Request& r) {
  auto v = encode(r);
  REQUIRE_MESSAGE(v.ok(), v.error().message);
  return *v;
}

BleValue ok(const Response& r) {
  auto v = encode(r);
  REQUIRE_MESSAGE(v.ok(), v.error().message);
  return *v;
}

Request request(Characteristic c, const Bytes& in) {
  auto r = decodeRequest(c, in);
  REQUIRE_MESSAGE(r.ok(), r.error().message);
  REQUIRE(std::holds_alternative<Request>(*r));
  return std::get<Request>(*r);
}

RobotMessage robot(Characteristic c, const Bytes& in) {
  auto r = decodeResponse(c, in);
  REQUIRE_MESSAGE(r.ok(), r.error().message);
  return *r;
}

Response response(Characteristic c, const Bytes& in) {
  auto m = robot(c, in);
  REQUIRE(std::holds_alternative<Response>(m));
  return std::get<Response>(m);
}

std::string requestError(Characteristic c, const Bytes& in) {
  auto r = decodeRequest(c, in);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error().characteristic == c);
  return r.error().message;
}

std::string responseError(Characteristic c, const Bytes& in) {
  auto r = decodeResponse(c, in);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error().characteristic == c);
  return r.error().message;
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("alphabot ble: the characteristics have the reference's UUIDs, names and sizes") {
  CHECK(characteristics().size() == 8);
  CHECK(std::string(info(Characteristic::DriveSteer).uuid) ==
        "a04295f7-eaa8-4536-b3a4-4e7ae4d72dc2");
  CHECK(std::string(info(Characteristic::PathFinding).name) == "PATH_FINDING");
  CHECK(info(Characteristic::PathFinding).size == 20);
  CHECK(info(Characteristic::Sensor).size == 5);
  CHECK(characteristicNamed("SENSOR") == Characteristic::Sensor);
  CHECK(characteristicNamed("target-navi") == Characteristic::TargetNavi);
  CHECK(characteristicNamed("117AD3A5-B257-4465-ABD4-7DC12A4CF77D") == Characteristic::PingClient);
  CHECK(characteristicByUuid(kObstacleUuid) == Characteristic::Obstacle);
  CHECK_FALSE(characteristicNamed("BATTERY"));
  for (const auto& i : characteristics()) CHECK(characteristicByUuid(i.uuid) == i.id);
}

TEST_CASE("alphabot ble: DRIVE_STEER carries steer first, then speed") {
  auto v = ok(Drive{.speed = 100, .steer = -20});
  CHECK(v.characteristic == Characteristic::DriveSteer);
  CHECK(v.bytes == bytes("ec 64"));
  CHECK(request(Characteristic::DriveSteer, bytes("ec 64")) == Request(Drive{100, -20}));
  CHECK(ok(Drive{.speed = -128, .steer = 127}).bytes == bytes("7f 80"));
}

TEST_CASE("alphabot ble: the distance request splits its 9-bit degree over two bytes") {
  CHECK(ok(MeasureDistance{0}).bytes == bytes("00 00 00 00 00"));
  CHECK(ok(MeasureDistance{255}).bytes == bytes("00 ff 00 00 00"));
  CHECK(ok(MeasureDistance{256}).bytes == bytes("01 00 00 00 00"));
  CHECK(ok(MeasureDistance{359}).bytes == bytes("01 67 00 00 00"));
  CHECK(ok(MeasureDistance{359}).characteristic == Characteristic::Sensor);
  for (int degree : {0, 1, 255, 256, 300, 359}) {
    auto v = ok(MeasureDistance{static_cast<std::int16_t>(degree)});
    CHECK(request(Characteristic::Sensor, v.bytes) ==
          Request(MeasureDistance{static_cast<std::int16_t>(degree)}));
  }
}

TEST_CASE("alphabot ble: a degree outside 0–359 is refused, naming the value") {
  auto e = encode(Request(MeasureDistance{360}));
  REQUIRE_FALSE(e.ok());
  CHECK(contains(e.error().message, "SENSOR"));
  CHECK(contains(e.error().message, "360"));
  CHECK_FALSE(encode(Request(MeasureDistance{-1})).ok());
  CHECK(contains(requestError(Characteristic::Sensor, bytes("01 68 00 00 00")), "360"));
  CHECK(contains(responseError(Characteristic::Sensor, bytes("81 ff 10 00 00")), "511"));
}

TEST_CASE("alphabot ble: the distance answer sets bit 7 and keeps the degree split") {
  CHECK(ok(Distance{.degree = 0, .distance = 42}).bytes == bytes("80 00 2a 00 00"));
  CHECK(ok(Distance{.degree = 255, .distance = 1}).bytes == bytes("80 ff 01 00 00"));
  CHECK(ok(Distance{.degree = 256, .distance = 200}).bytes == bytes("81 00 c8 00 00"));
  CHECK(ok(Distance{.degree = 359, .distance = 255}).bytes == bytes("81 67 ff 00 00"));
  CHECK(response(Characteristic::Sensor, bytes("81 67 ff 00 00")) == Response(Distance{359, 255}));
  CHECK(response(Characteristic::Sensor, bytes("81 00 c8 00 00")) == Response(Distance{256, 200}));
  // a distance over 255 cm has no byte on BLE
  auto e = encode(Response(Distance{.degree = 10, .distance = 256}));
  REQUIRE_FALSE(e.ok());
  CHECK(contains(e.error().message, "256"));
}

TEST_CASE("alphabot ble: the request/answer bit tells a client's request from the robot's answer") {
  // the same bytes but bit 7: a request to the robot, an answer to the client
  CHECK(request(Characteristic::Sensor, bytes("01 2c 00 00 00")) == Request(MeasureDistance{300}));
  CHECK(response(Characteristic::Sensor, bytes("81 2c 37 00 00")) == Response(Distance{300, 55}));
  CHECK(contains(responseError(Characteristic::Sensor, bytes("01 2c 00 00 00")), "bit 7 is clear"));
  CHECK(contains(requestError(Characteristic::Sensor, bytes("81 2c 00 00 00")), "bit 7 is set"));
  // bit 7 is the only difference between request and answer encodings
  auto req = ok(MeasureDistance{300}).bytes;
  auto ans = ok(Distance{300, 0}).bytes;
  CHECK((req[0] ^ ans[0]) == 0x80);
}

TEST_CASE("alphabot ble: SENSOR answers of every kind") {
  CHECK(ok(Compass{.degree = 270}).bytes == bytes("90 0e 01 00 00"));
  CHECK(response(Characteristic::Sensor, bytes("90 0e 01 00 00")) == Response(Compass{270}));
  CHECK(ok(MapSize{.length = 200, .width = 150}).bytes == bytes("a0 c8 96 00 00"));
  CHECK(response(Characteristic::Sensor, bytes("a0 c8 96 00 00")) == Response(MapSize{200, 150}));
  CHECK(ok(Position{.x = -5, .y = 300}).bytes == bytes("b0 fb ff 2c 01"));
  CHECK(response(Characteristic::Sensor, bytes("b0 fb ff 2c 01")) == Response(Position{-5, 300}));
  CHECK(ok(AnchorPosition{.id = 3, .x = 100, .y = 0}).bytes == bytes("c3 64 00 00 00"));
  CHECK(response(Characteristic::Sensor, bytes("c3 64 00 00 00")) ==
        Response(AnchorPosition{3, 100, 0}));
  CHECK(contains(responseError(Characteristic::Sensor, bytes("d0 00 00 00 00")),
                 "unknown sensor kind 5"));
  CHECK(contains(responseError(Characteristic::Sensor, bytes("95 00 00 00 00")),
                 "bits 3–0 must be 0 for kind compass"));
}

TEST_CASE("alphabot ble: SENSOR requests: queries by kind, and the anchor with its id") {
  auto q = encode(SensorQuery{SensorKind::Compass});
  REQUIRE(q.ok());
  CHECK(q->bytes == bytes("10 00 00 00 00"));
  CHECK(encode(SensorQuery{SensorKind::Positioning})->bytes == bytes("30 00 00 00 00"));
  CHECK(encode(SensorQuery{SensorKind::MapSize})->bytes == bytes("20 00 00 00 00"));
  CHECK_FALSE(encode(SensorQuery{SensorKind::Distance}).ok());
  CHECK_FALSE(encode(SensorQuery{SensorKind::Anchor}).ok());
  auto d = decodeRequest(Characteristic::Sensor, bytes("30 00 00 00 00"));
  REQUIRE(d.ok());
  CHECK(std::get<SensorQuery>(*d) == SensorQuery{SensorKind::Positioning});

  CHECK(ok(SetAnchor{.id = 15, .x = -100, .y = 250}).bytes == bytes("4f 9c ff fa 00"));
  CHECK(request(Characteristic::Sensor, bytes("4f 9c ff fa 00")) ==
        Request(SetAnchor{15, -100, 250}));
  auto e = encode(Request(SetAnchor{.id = 16, .x = 0, .y = 0}));
  REQUIRE_FALSE(e.ok());
  CHECK(contains(e.error().message, "anchor id 16"));
}

TEST_CASE("alphabot ble: TOGGLE is two bytes, settings then logging") {
  Toggles t{.settings = 0x90, .logging = 0x81};  // compass calibration + collision avoidance
  CHECK(ok(SetToggles{t}).bytes == bytes("90 81"));
  CHECK(ok(SetToggles{t}).characteristic == Characteristic::Toggle);
  CHECK(request(Characteristic::Toggle, bytes("90 81")) == Request(SetToggles{t}));
  CHECK(std::get<TogglesReport>(robot(Characteristic::Toggle, bytes("90 81"))) == TogglesReport{t});
  CHECK(encode(TogglesReport{t}).bytes == bytes("90 81"));
  CHECK(contains(requestError(Characteristic::Toggle, bytes("90")), "1 byte, expected 2"));
}

TEST_CASE("alphabot ble: OBSTACLE sub-commands with one-byte width and height") {
  auto add = ok(AddObstacle{.x = 100, .y = -20, .width = 30, .height = 255});
  CHECK(add.characteristic == Characteristic::Obstacle);
  CHECK(add.bytes == bytes("01 64 00 ec ff 1e ff"));
  CHECK(request(Characteristic::Obstacle, add.bytes) == Request(AddObstacle{100, -20, 30, 255}));
  CHECK(ok(RemoveObstacleById{7}).bytes == bytes("03 00 00 00 00 07"));
  CHECK(request(Characteristic::Obstacle, bytes("03 00 00 00 00 07")) ==
        Request(RemoveObstacleById{7}));
  CHECK(ok(RemoveObstacleAt{.x = 1, .y = 2}).bytes == bytes("03 01 00 02 00 ff"));
  CHECK(request(Characteristic::Obstacle, bytes("03 01 00 02 00 ff")) ==
        Request(RemoveObstacleAt{1, 2}));
  CHECK(ok(ClearObstacles{}).bytes == bytes("04"));
  CHECK(request(Characteristic::Obstacle, bytes("04")) == Request(ClearObstacles{}));
  // padded to the characteristic's 7 bytes
  CHECK(request(Characteristic::Obstacle, bytes("04 00 00 00 00 00 00")) ==
        Request(ClearObstacles{}));

  auto registered = ok(ObstacleRegistered{.id = 9, .x = 100, .y = 50, .width = 30, .height = 40});
  CHECK(registered.bytes == bytes("02 09 64 00 32 00 1e 28"));
  CHECK(response(Characteristic::Obstacle, registered.bytes) ==
        Response(ObstacleRegistered{9, 100, 50, 30, 40}));
}

TEST_CASE("alphabot ble: an obstacle wider or higher than 255 is refused, naming the value") {
  auto w = encode(Request(AddObstacle{.x = 0, .y = 0, .width = 300, .height = 10}));
  REQUIRE_FALSE(w.ok());
  CHECK(contains(w.error().message, "OBSTACLE"));
  CHECK(contains(w.error().message, "width 300"));
  auto h = encode(Request(AddObstacle{.x = 0, .y = 0, .width = 10, .height = 256}));
  REQUIRE_FALSE(h.ok());
  CHECK(contains(h.error().message, "height 256"));
  CHECK_FALSE(encode(Request(RemoveObstacleById{255})).ok());
}

TEST_CASE("alphabot ble: OBSTACLE errors name the sub-command and the lengths") {
  CHECK(contains(requestError(Characteristic::Obstacle, {}), "0 bytes"));
  CHECK(contains(requestError(Characteristic::Obstacle, bytes("01 00 00")),
                 "add (1) has 3 bytes, expected 7"));
  CHECK(contains(requestError(Characteristic::Obstacle, bytes("09")), "unknown sub-command 9"));
  CHECK(contains(requestError(Characteristic::Obstacle, bytes("02 01 00 00 00 00 01 01")),
                 "robot's answer"));
  CHECK(contains(responseError(Characteristic::Obstacle, bytes("02 01 00 00")),
                 "registered (2) has 4 bytes, expected 8"));
  CHECK(contains(responseError(Characteristic::Obstacle, bytes("01 00 00 00 00 01 01")),
                 "not an answer"));
}

TEST_CASE("alphabot ble: CALIBRATE 1 and 2 are requests, 0 is the robot's 'finished'") {
  CHECK(ok(CalibrateSteering{}).bytes == bytes("01"));
  CHECK(ok(CalibrateCompass{}).bytes == bytes("02"));
  CHECK(ok(CalibrateCompass{}).characteristic == Characteristic::Calibrate);
  CHECK(request(Characteristic::Calibrate, bytes("01")) == Request(CalibrateSteering{}));
  CHECK(request(Characteristic::Calibrate, bytes("02")) == Request(CalibrateCompass{}));
  CHECK(ok(CalibrationFinished{}).bytes == bytes("00"));
  CHECK(response(Characteristic::Calibrate, bytes("00")) == Response(CalibrationFinished{}));
  CHECK(contains(requestError(Characteristic::Calibrate, bytes("03")), "unknown value 3"));
  CHECK(contains(responseError(Characteristic::Calibrate, bytes("01")), "not an answer"));
  CHECK(contains(requestError(Characteristic::Calibrate, bytes("01 02")), "2 bytes, expected 1"));
}

TEST_CASE("alphabot ble: TARGET_NAVI is x and y, two bytes each, little-endian") {
  auto v = ok(NavigateTo{.x = 300, .y = -2});
  CHECK(v.characteristic == Characteristic::TargetNavi);
  CHECK(v.bytes == bytes("2c 01 fe ff"));
  CHECK(request(Characteristic::TargetNavi, v.bytes) == Request(NavigateTo{300, -2}));
  CHECK(contains(requestError(Characteristic::TargetNavi, bytes("2c 01 fe")),
                 "TARGET_NAVI: 3 bytes, expected 4"));
}

TEST_CASE("alphabot ble: PATH_FINDING is a count and up to four waypoints in 20 bytes") {
  Path path{{{100, 50}, {-20, 300}}};
  auto v = ok(path);
  CHECK(v.characteristic == Characteristic::PathFinding);
  CHECK(v.bytes == bytes("02 64 00 32 00 ec ff 2c 01 00 00 00 00 00 00 00 00 00 00 00"));
  CHECK(response(Characteristic::PathFinding, v.bytes) == Response(path));
  CHECK(response(Characteristic::PathFinding, bytes("00")) == Response(Path{}));
  Path four{{{1, 1}, {2, 2}, {3, 3}, {4, 4}}};
  CHECK(response(Characteristic::PathFinding, ok(four).bytes) == Response(four));
  auto five = encode(Response(Path{{{1, 1}, {2, 2}, {3, 3}, {4, 4}, {5, 5}}}));
  REQUIRE_FALSE(five.ok());
  CHECK(contains(five.error().message, "5 waypoints"));
  CHECK(std::holds_alternative<PathPending>(
      robot(Characteristic::PathFinding, encode(PathPending{}).bytes)));
  CHECK(contains(responseError(Characteristic::PathFinding, bytes("05 00")), "count 5"));
  CHECK(contains(responseError(Characteristic::PathFinding, bytes("02 01 00 01 00")),
                 "5 bytes for 2 waypoints, expected at least 9"));
  CHECK(contains(responseError(Characteristic::PathFinding, Bytes(21, 0)), "21 bytes"));
}

TEST_CASE("alphabot ble: a ping cannot be written; PINGCLIENT is the robot's heartbeat") {
  auto e = encode(Request(Ping{1234}));
  REQUIRE_FALSE(e.ok());
  CHECK(e.error().characteristic == Characteristic::PingClient);
  CHECK(contains(e.error().message, "read of PINGCLIENT"));
  CHECK_FALSE(encode(Response(PingReply{1})).ok());
  CHECK(std::get<Heartbeat>(robot(Characteristic::PingClient, bytes("2a"))) == Heartbeat{42});
  CHECK(encode(Heartbeat{7}).bytes == bytes("07"));
  CHECK(contains(requestError(Characteristic::PingClient, bytes("01")), "read/notify only"));
  CHECK(contains(requestError(Characteristic::PathFinding, bytes("01")), "read only"));
  CHECK(contains(responseError(Characteristic::DriveSteer, bytes("01 02")), "never notified"));
}

TEST_CASE("alphabot ble: wrong lengths are errors naming the characteristic and both lengths") {
  CHECK(requestError(Characteristic::DriveSteer, bytes("01")) == "DRIVE_STEER: 1 byte, expected 2");
  CHECK(requestError(Characteristic::Sensor, bytes("00 00 00")) == "SENSOR: 3 bytes, expected 5");
  CHECK(responseError(Characteristic::Sensor, Bytes(6, 0x80)) == "SENSOR: 6 bytes, expected 5");
  CHECK(responseError(Characteristic::PingClient, {}) == "PINGCLIENT: 0 bytes, expected 1");
}

TEST_CASE("alphabot ble: every request round-trips through its characteristic") {
  std::vector<Request> all = {Drive{-3, 4},
                              MeasureDistance{123},
                              CalibrateSteering{},
                              CalibrateCompass{},
                              SetToggles{{0xfc, 0xff}},
                              SetAnchor{2, -7, 8},
                              NavigateTo{-300, 400},
                              AddObstacle{5, 6, 7, 8},
                              RemoveObstacleById{3},
                              RemoveObstacleAt{-1, -2},
                              ClearObstacles{}};
  for (const auto& r : all) {
    auto v = ok(r);
    CHECK(v.bytes.size() <= info(v.characteristic).size);
    CHECK(request(v.characteristic, v.bytes) == r);
  }
}

TEST_CASE("alphabot ble: decoding is total on every characteristic (random bytes)") {
  std::mt19937 rng(7);
  for (const auto& i : characteristics()) {
    for (int n = 0; n < 2000; ++n) {
      Bytes in(rng() % 24);
      for (auto& b : in) b = static_cast<std::uint8_t>(rng());
      auto a = decodeRequest(i.id, in);
      auto b = decodeResponse(i.id, in);
      if (!a.ok()) CHECK(contains(a.error().message, i.name));
      if (!b.ok()) CHECK(contains(b.error().message, i.name));
      auto j = decodeBle(i.name, in);
      if (j.ok()) CHECK((*j)["characteristic"] == i.name);
    }
  }
}

TEST_CASE("alphabot ble: decodeBle gives JSON in the direction the bytes say") {
  auto d = decodeBle("SENSOR", bytes("81 67 ff 00 00"));
  REQUIRE(d.ok());
  CHECK((*d)["direction"] == "response");
  CHECK(d->count("packet") == 0);
  CHECK((*d)["degree"] == 359);
  CHECK((*d)["distance"] == 255);
  CHECK((*d)["uuid"] == kSensorUuid);
  auto r = decodeBle("sensor", bytes("01 67 00 00 00"));
  REQUIRE(r.ok());
  CHECK((*r)["direction"] == "request");
  CHECK((*r)["degree"] == 359);
  auto t = decodeBle("TOGGLE", bytes("10 80"));
  REQUIRE(t.ok());
  CHECK((*t)["direction"] == "request");
  CHECK((*t)["toggles"]["settings"] == 0x10);
  CHECK((*t)["toggles"]["logging"] == 0x80);
  auto h = decodeBle("PINGCLIENT", bytes("07"));
  REQUIRE(h.ok());
  CHECK((*h)["name"] == "heartbeat");
  CHECK((*h)["value"] == 7);
  auto p = decodeBle("PATH_FINDING", ok(Path{{{1, 2}}}).bytes);
  REQUIRE(p.ok());
  CHECK((*p)["waypoints"][0]["y"] == 2);
  auto unknown = decodeBle("BATTERY", bytes("00"));
  REQUIRE_FALSE(unknown.ok());
  CHECK(contains(unknown.error(), "'BATTERY' is not an Alphabot BLE characteristic"));
  CHECK(contains(unknown.error(), "PATH_FINDING"));
  auto bad = decodeBle("DRIVE_STEER", bytes("01"));
  REQUIRE_FALSE(bad.ok());
  CHECK(bad.error() == "DRIVE_STEER: 1 byte, expected 2");
}
