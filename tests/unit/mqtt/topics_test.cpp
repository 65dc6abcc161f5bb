// The publications a car's messages and life make, the identities, and the reading side
// (engine/mqtt/topics.cpp, controller_events.cpp, readers.cpp).
#include "engine/mqtt/topics.hpp"

#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "tests/support/hostile_payloads.hpp"

using namespace pitwall;
using namespace pitwall::topics;

namespace {

constexpr Millis kNow = 1700000000123;
const std::string kCar = "e85a0f112233";
const std::vector<std::string> kCars{kCar, "sim-0000002a"};

Publication ev(const std::string& suffix, const std::string& value) {
  return {"Anki/Car/" + kCar + "/E/" + suffix,
          "{\"timestamp\":1700000000123,\"value\":" + value + "}", 0, false};
}
Publication st(const std::string& suffix, const std::string& value) {
  return {"Anki/Car/" + kCar + "/S/" + suffix,
          "{\"timestamp\":1700000000123,\"value\":" + value + "}", 1, true};
}

// The seed's controller's whole-message event: E/Messages/ANKI_VEHICLE_MSG_V2C_<name>.
Publication whole(const std::string& name, const std::string& fields) {
  return {"Anki/Car/" + kCar + "/E/Messages/ANKI_VEHICLE_MSG_V2C_" + name, fields, 0, false};
}

}  // namespace

TEST_CASE("mqtt topics: a BLE address becomes the seed's device id, a sim address stays readable") {
  CHECK(carId("ble:E8:5A:0F:11:22:33") == "e85a0f112233");
  CHECK(carId("E8:5A:0F:11:22:33") == "e85a0f112233");
  CHECK(carId("sim:0000002a") == "sim-0000002a");
  CHECK(carId("tcp:10.0.0.1:5000/x+y#z") == "tcp-10.0.0.1-5000_x_y_z");
  CHECK(carId("all") == "_all");
  CHECK(carId("") == "_");
  CHECK(hostId("pit 1/+#") == "pit_1___");
  CHECK(hostId("") == "_");
}

TEST_CASE("mqtt topics: a position update gives the six seed events and speed and lane status") {
  anki::PositionUpdate m;
  m.location_id = 7;
  m.piece_id = 33;
  m.offset_mm = -23.1f;
  m.speed_mm_s = 612;
  m.last_desired_lane_change_speed_mm_s = 300;
  m.last_desired_speed_mm_s = 600;
  auto ps = fromMessage(kCar, m, std::nullopt, kNow);
  CHECK(ps == std::vector<Publication>{
                  ev("speed", "612"),
                  ev("last_desired_speed", "600"),
                  ev("track_piece_id", "33"),
                  ev("track_location_id", "7"),
                  ev("lane/offset/actual", "-23.1"),
                  ev("lane/desired_lane_change_speed", "300"),
                  st("Speed/Actual", "612"),
                  st("Lane/Actual", "-23.1"),
                  whole("LOCALIZATION_POSITION_UPDATE",
                        R"({"message_id":39,"timestamp":1700000000123,"offset":-23.1,"speed":612,)"
                        R"("flag":0,"pieceId":33,"pieceLocation":7,"last_des_speed":600,)"
                        R"("last_rec_lane_change_cmd":0,"last_exe_lane_change_cmd":0,)"
                        R"("last_des_lane_change_speed":300,"isReverse":false})"),
              });
}

TEST_CASE("mqtt topics: a transition update gives its fields as events and the lane status") {
  anki::TransitionUpdate m;
  m.offset_mm = 44.5f;
  m.last_desired_lane_change_speed_mm_s = 250;
  m.average_follow_line_drift_px = -3;
  m.had_lane_change_activity = 1;
  m.uphill_counter = 2;
  m.downhill_counter = 4;
  m.left_wheel_distance_cm = 21;
  m.right_wheel_distance_cm = 22;
  auto ps = fromMessage(kCar, m, std::nullopt, kNow);
  CHECK(ps == std::vector<Publication>{
                  ev("lane/offset/actual", "44.5"),
                  ev("lane/desired_lane_change_speed", "250"),
                  ev("ave_follow_line_drift_pixels", "-3"),
                  ev("had_lane_change_activity", "1"),
                  ev("uphill_counter", "2"),
                  ev("downhill_counter", "4"),
                  ev("left_wheel_dist_cm", "21"),
                  ev("right_wheel_dist_cm", "22"),
                  st("Lane/Actual", "44.5"),
                  whole("LOCALIZATION_TRANSITION_UPDATE",
                        R"({"message_id":41,"timestamp":1700000000123,"offset":44.5,)"
                        R"("last_recv_lane_change_id":0,"last_exec_lane_change_id":0,)"
                        R"("last_desired_lane_change_speed_mm_per_sec":250,)"
                        R"("ave_follow_line_drift_pixels":-3,"had_lane_change_activity":1,)"
                        R"("uphill_counter":2,"downhill_counter":4,"left_wheel_dist_cm":21,)"
                        R"("right_wheel_dist_cm":22})"),
              });
}

TEST_CASE("mqtt topics: an intersection update gives its code and distances") {
  anki::IntersectionUpdate m;
  m.intersection_code = 3;
  m.mm_since_last_transition_bar = 120;
  m.mm_since_last_intersection_code = 450;
  m.offset_mm = 23;
  m.is_exiting = 1;
  CHECK(fromMessage(kCar, m, std::nullopt, kNow) ==
        std::vector<Publication>{
            ev("lane/offset/actual", "23.0"), ev("intersection_code", "3"),
            ev("mm_since_last_transition_bar", "120"), ev("mm_since_last_intersection_code", "450"),
            whole("LOCALIZATION_INTERSECTION_UPDATE",
                  R"({"message_id":42,"timestamp":1700000000123,"offset":23.0,)"
                  R"("intersection_code":3,"is_exiting":1,"mm_since_last_transition_bar":120,)"
                  R"("mm_since_last_intersection_code":450})")});
  SUBCASE("the older layout has no distance since the last code, so none is published") {
    m.mm_since_last_intersection_code.reset();
    auto ps = fromMessage(kCar, m, std::nullopt, kNow);
    CHECK(ps.size() == 4);
    CHECK(ps.back().payload.find("mm_since_last_intersection_code") == std::string::npos);
  }
}

TEST_CASE("mqtt topics: delocalized is an event with the timestamp only") {
  CHECK(fromMessage(kCar, anki::Delocalized{}, std::nullopt, kNow) ==
        std::vector<Publication>{
            {"Anki/Car/" + kCar + "/E/Delocalized", "{\"timestamp\":1700000000123}", 0, false},
            whole("VEHICLE_DELOCALIZED", R"({"message_id":43,"timestamp":1700000000123})")});
}

TEST_CASE("mqtt topics: replies and reports become retained status") {
  CHECK(fromMessage(kCar, anki::VersionResponse{0x2b6e}, std::nullopt, kNow) ==
        std::vector<Publication>{
            st("Version", "11118"),
            whole("VERSION_RESPONSE",
                  R"({"message_id":25,"timestamp":1700000000123,"value":11118})")});
  CHECK(fromMessage(kCar, anki::BatteryResponse{3912}, std::nullopt, kNow) ==
        std::vector<Publication>{
            st("BatteryLevel", "3912"),
            whole("BATTERY_LEVEL_RESPONSE",
                  R"({"message_id":27,"timestamp":1700000000123,"value":3912})")});
  CHECK(fromMessage(kCar, anki::OffsetUpdate{-68.0f, 1}, std::nullopt, kNow) ==
        std::vector<Publication>{st("Lane/Actual", "-68.0")});
  CHECK(fromMessage(kCar, anki::SpeedUpdate{600, 1000, 598}, std::nullopt, kNow) ==
        std::vector<Publication>{st("Speed/Actual", "598")});
  anki::CarStatus status;
  status.on_track = true;
  status.on_charger = false;
  CHECK(
      fromMessage(kCar, status, std::nullopt, kNow) ==
      std::vector<Publication>{
          {"Anki/Car/" + kCar + "/S/CarStatus",
           R"({"timestamp":1700000000123,"online":true,"charging":false,"onTrack":true})", 1, true},
          whole("VEHICLE_STATUS", R"({"message_id":63,"timestamp":1700000000123,"online":true,)"
                                  R"("charging":0,"onTrack":1})")});
}

TEST_CASE("mqtt topics: a ping response carries the round-trip time in ms, or null") {
  // S/PingResp where the controller's clients read it, S/PingResponse as pitwall published it
  CHECK(fromMessage(kCar, anki::PingResponse{}, 0.0125, kNow) ==
        std::vector<Publication>{
            {"Anki/Car/" + kCar + "/S/PingResp", R"({"timestamp":1700000000123,"rtt_ms":12.5})", 1,
             true},
            {"Anki/Car/" + kCar + "/S/PingResponse", R"({"timestamp":1700000000123,"rtt_ms":12.5})",
             1, true},
            whole("PING_RESPONSE", R"({"message_id":23,"timestamp":1700000000123})")});
  CHECK(fromMessage(kCar, anki::PingResponse{}, std::nullopt, kNow).at(0).payload ==
        R"({"timestamp":1700000000123,"rtt_ms":null})");
}

TEST_CASE("mqtt topics: messages with no place in the tree publish nothing") {
  CHECK(fromMessage(kCar, anki::Collision{}, std::nullopt, kNow).empty());
  CHECK(fromMessage(kCar, anki::SetSpeed{600, 1000, false}, std::nullopt, kNow).empty());
  CHECK(fromMessage(kCar, anki::LaneChangeUpdate{}, std::nullopt, kNow).empty());
}

TEST_CASE("mqtt topics: commands sent publish the desired speed and lane") {
  CHECK(commandStatus(kCar, anki::SetSpeed{600, 1000, false}, kNow) ==
        std::vector<Publication>{st("Speed/Desired", "600")});
  CHECK(commandStatus(kCar, anki::ChangeLane{300, 3000, -23.5f, 0, 0}, kNow) ==
        std::vector<Publication>{st("Lane/Desired", "-23.5")});
  CHECK(commandStatus(kCar, anki::SetOffset{12.0f}, kNow) ==
        std::vector<Publication>{st("Lane/Desired", "12.0")});
  CHECK(commandStatus(kCar, anki::PingRequest{}, kNow).empty());
}

TEST_CASE("mqtt topics: a car that joins publishes its information, discovery time and status") {
  CarInfo info{kCar, "E8:5A:0F:11:22:33", 0x12345678, 9, 0xBEEF, "skull", true, "pit1"};
  CarState state;
  state.on_charger = true;
  auto ps = carJoined(info, state, kNow);
  CHECK(
      ps ==
      std::vector<Publication>{
          {"Anki/Car/" + kCar + "/S/Information",
           R"({"address":"E8:5A:0F:11:22:33","identifier":305419896,"model":"Skull",)"
           R"("modelId":9,"productId":48879,"name":"skull","bridge":"pitwall","host":"pit1"})",
           1, true},
          {"Anki/Car/" + kCar + "/S/DiscoveryTime", R"({"timestamp":1700000000123})", 1, true},
          {"Anki/Car/" + kCar + "/S/CarStatus",
           R"({"timestamp":1700000000123,"online":true,"charging":true,"onTrack":false})", 1, true},
      });
  CHECK(carLeft(kCar, state, kNow) ==
        Publication{"Anki/Car/" + kCar + "/S/CarStatus",
                    R"({"timestamp":1700000000123,"online":false,"charging":true,"onTrack":false})",
                    1, true});
}

TEST_CASE("mqtt topics: host status, will, car list and discovery event") {
  CHECK(hostOnline("pit1") ==
        Publication{"Anki/Host/pit1/S/HostStatus", R"({"value":true})", 1, true});
  CHECK(hostWill("pit1") ==
        Publication{"Anki/Host/pit1/S/HostStatus", R"({"value":false})", 1, true});
  // a bare array, as the seed's controller publishes it and its clients iterate it
  CHECK(hostCars("pit1", kCars) ==
        Publication{"Anki/Host/pit1/S/Cars", R"(["e85a0f112233","sim-0000002a"])", 1, true});
  CHECK(hostCars("pit1", {}).payload == "[]");
  CHECK(carConnected("pit1", kCar, kNow) ==
        Publication{"Anki/Host/pit1/E/CarConnected",
                    R"({"timestamp":1700000000123,"Car":"e85a0f112233"})", 0, false});
  CHECK(carDisconnected("pit1", kCar, kNow) ==
        Publication{"Anki/Host/pit1/E/CarDisconnected",
                    R"({"timestamp":1700000000123,"Car":"e85a0f112233"})", 0, false});
  CHECK(carDiscovered("pit1", kCar, kNow) ==
        Publication{"Anki/Host/pit1/E/CarDiscovered",
                    R"({"timestamp":1700000000123,"Car":"e85a0f112233"})", 0, false});
}

TEST_CASE("mqtt topics: a vehicle frame is also published whole as pitwall's E/frame event") {
  std::vector<std::uint8_t> frame{0x03, 0x19, 0x6e, 0x2b};
  CHECK(frameEvent(kCar, frame, kNow) == ev("frame", "\"03196e2b\""));
  auto back = readFrameEvent(frameEvent(kCar, frame, kNow).payload);
  REQUIRE(back);
  CHECK(*back == frame);
  CHECK(readFrameEvent(R"({"timestamp":1,"value":"0319x"})").error() ==
        "odd number of hex digits (5)");
  CHECK(readFrameEvent(R"({"timestamp":1,"value":"03zz"})").error() == "\"zz\" is not a hex byte");
  CHECK(readFrameEvent(R"({"timestamp":1})").error() == "missing key \"value\"");
  CHECK(readFrameEvent("[").error().starts_with("payload is not JSON: "));
}

TEST_CASE("mqtt topics: the reading side splits topics and reads status payloads") {
  auto car = splitTopic("Anki/Car/sim-0000002a/S/Speed/Actual");
  REQUIRE(car);
  CHECK(car->kind == TopicParts::Kind::Car);
  CHECK(car->id == "sim-0000002a");
  CHECK(car->rest == "S/Speed/Actual");
  auto host = splitTopic("Anki/Host/pit1/S/Cars");
  REQUIRE(host);
  CHECK(host->kind == TopicParts::Kind::Host);
  CHECK(host->rest == "S/Cars");
  CHECK_FALSE(splitTopic("Anki/Car/x"));
  CHECK_FALSE(splitTopic("Anki/Boat/x/S"));
  CHECK_FALSE(splitTopic("pitwall/sync/1"));

  CarInfo info{kCar, "E8:5A:0F:11:22:33", 0x12345678, 9, 0xBEEF, "skull", false, ""};
  auto joined = carJoined(info, CarState{}, kNow);
  auto read = readInformation(kCar, joined[0].payload);
  REQUIRE(read);
  CHECK(read->name == "skull");
  CHECK(read->identifier == 0x12345678u);
  CHECK(read->model_id == 9);
  CHECK(read->address == "E8:5A:0F:11:22:33");
  CHECK_FALSE(read->pitwall);
  // a car's kind is what its S/Information says: a pitwall bridge names itself and its host
  info.pitwall = true;
  info.host = "pit1";
  auto pitwall = readInformation(kCar, carJoined(info, CarState{}, kNow)[0].payload);
  REQUIRE(pitwall);
  CHECK(pitwall->pitwall);
  CHECK(pitwall->host == "pit1");
  // the seed's payload, without pitwall's name, bridge or host: the seed's controller's car
  auto seed =
      readInformation(kCar, R"({"address":"a","identifier":1,"model":"Skull","modelId":9})");
  REQUIRE(seed);
  CHECK(seed->name.empty());
  CHECK_FALSE(seed->pitwall);
  CHECK(readInformation(kCar, R"({"address":"a","identifier":-1,"modelId":9})").error() ==
        "\"identifier\" must be an integer 0..4294967295, not -1");
  CHECK(readInformation(kCar, R"({"address":"a","identifier":1,"modelId":256})").error() ==
        "\"modelId\" must be an integer 0..255, not 256");

  CarState state;
  state.on_track = true;
  auto online = readCarStatus(carOnline(kCar, state, kNow).payload);
  REQUIRE(online);
  CHECK(online->online);
  CHECK(online->onTrack);
  CHECK_FALSE(readCarStatus(carLeft(kCar, state, kNow).payload)->online);
  CHECK(readCarStatus("{}").error() == "missing key \"online\"");

  CHECK(*readHostStatus(hostOnline("pit1").payload));
  CHECK_FALSE(*readHostStatus(hostWill("pit1").payload));
  std::vector<std::string> cars{"a", "b"};
  CHECK(*readHostCars(hostCars("pit1", cars).payload) == cars);
  CHECK(readHostCars("{}")->empty());                                    // the controller's none
  CHECK(*readHostCars(R"({"timestamp":1,"value":["a","b"]})") == cars);  // earlier pitwall
  CHECK(readHostCars("[1]").error() == "a car id must be a string, not an integer (1)");
  CHECK(readHostCars(R"({"value":[1]})").error() ==
        "a car id must be a string, not an integer (1)");
  CHECK(readHostCars(R"({"x":1})").error() == "must be an array of car ids, not an object");
  CHECK(readHostCars("7").error() == "must be an array of car ids, not an integer (7)");
  CHECK(readInformation(kCar, R"({"address":"a","identifier":1,"modelId":9,"bridge":"pitwall"})")
            .error() == "missing key \"host\" (a pitwall bridge names its host)");
  CHECK(readInformation(kCar, R"({"address":"a","identifier":1,"modelId":9,"bridge":"pitwall",)"
                              R"("host":7})")
            .error() == "\"host\" has the wrong type (7) (a pitwall bridge names its host)");
  // the controller blanks S/Information when it drops a car
  auto blank = readInformation(
      kCar, R"({"address":"","identifier":"","model":"","modelId":"","productId":""})");
  REQUIRE(blank);
  CHECK(blank->address.empty());
}

TEST_CASE("mqtt topics: quote() shows at most so many bytes, printable, invalid bytes as \\xNN") {
  CHECK(quote("speed") == "speed");
  CHECK(quote("é ✓ 🏁") == "é ✓ 🏁");
  CHECK(quote("a\xff"
              "b\n\x01") == "a\\xffb\\x0a\\x01");
  CHECK(quote("\xc3\x28") == "\\xc3(");               // a lead byte without its continuation
  CHECK(quote("\xed\xa0\x80") == "\\xed\\xa0\\x80");  // a UTF-16 surrogate
  CHECK(quote("\xc0\xaf") == "\\xc0\\xaf");           // an overlong '/'
  CHECK(quote(std::string(100, 'x')) == std::string(80, 'x') + "…");
  CHECK(quote("abcdé", 5) == "abcd\\xc3…");  // a character cut by the limit
  CHECK(quote(std::string(5, '\0'), 3) == "\\x00\\x00\\x00…");
}

TEST_CASE("mqtt topics: the readers refuse hostile payloads with an error, never an exception") {
  for (const auto& bad : pitwall::testing::hostilePayloads()) {
    CAPTURE(bad.name);
    CHECK_FALSE(readInformation(kCar, bad.payload));
    CHECK_FALSE(readCarStatus(bad.payload));
    CHECK_FALSE(readHostStatus(bad.payload));
    CHECK_FALSE(readHostCars(bad.payload));
    auto frame = readFrameEvent(bad.payload);
    REQUIRE_FALSE(frame);
    CHECK(frame.error().size() < 600);
  }
  // a pair that cuts a character in two is shown escaped
  CHECK(readFrameEvent("{\"value\":\"0\xc3\xa9"
                       "f\"}")
            .error() == "\"0\\xc3\" is not a hex byte");
  CHECK(readCarStatus(pitwall::testing::nested(3, ""), PayloadLimits{100, 2})
            .error()
            .starts_with("payload nests objects and arrays more than 2 deep"));
}

TEST_CASE("mqtt topics: E/Messages reads back to the message it was made from") {
  anki::PositionUpdate position{7, 33, -23.5f, 612, 0x47, 2, 1, 300, 600};
  anki::TransitionUpdate transition;
  transition.offset_mm = 44.5f;
  transition.last_desired_lane_change_speed_mm_s = 250;
  transition.average_follow_line_drift_px = -3;
  transition.uphill_counter = 2;
  transition.right_wheel_distance_cm = 22;
  anki::IntersectionUpdate intersection;
  intersection.offset_mm = 23;
  intersection.intersection_code = 3;
  intersection.mm_since_last_transition_bar = 120;
  intersection.mm_since_last_intersection_code = 450;
  anki::CarStatus status;
  status.on_track = true;
  std::vector<anki::Message> messages{position,
                                      transition,
                                      intersection,
                                      anki::Delocalized{},
                                      anki::PingResponse{},
                                      anki::VersionResponse{0x2b6e},
                                      anki::BatteryResponse{3912},
                                      status};
  for (const auto& m : messages) {
    auto ps = fromMessage(kCar, m, std::nullopt, kNow);
    const auto& event = ps.back();
    const std::string prefix = "Anki/Car/" + kCar + "/E/Messages/";
    REQUIRE(event.topic.starts_with(prefix));
    auto name = event.topic.substr(prefix.size());
    CHECK(name == messageEventName(m));
    auto back = readMessageEvent(name, event.payload);
    REQUIRE(back);
    REQUIRE(*back);
    CHECK(**back == m);
  }
  // a name without a message of its own is not read at all
  auto other = readMessageEvent("ANKI_VEHICLE_MSG_V2C_SOMETHING_NEW", "not json");
  REQUIRE(other);
  CHECK_FALSE(*other);
  // the controller's payload as it publishes it: "timestamp":Date.now is dropped by
  // JSON.stringify, the rest is there
  auto controller = readMessageEvent(
      "ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE",
      R"({"message_id":39,"offset":-68,"speed":500,"flag":71,"pieceId":36,"pieceLocation":12,)"
      R"("isReverse":false,"last_des_speed":500,"last_rec_lane_change_cmd":0,)"
      R"("last_exe_lane_change_cmd":0,"last_des_lane_change_speed":0})");
  REQUIRE(controller);
  auto* p = std::get_if<anki::PositionUpdate>(&**controller);
  REQUIRE(p);
  CHECK(p->piece_id == 36);
  CHECK(p->speed_mm_s == 500);
  CHECK(p->offset_mm == -68.0f);
  // bad values are named
  CHECK(readMessageEvent("ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE", R"({"speed":-1})")
            .error() == "\"speed\" must be an integer 0..65535, not -1");
  CHECK(readMessageEvent("ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE", R"({"pieceId":"36"})")
            .error() == "\"pieceId\" must be a number, not a string (\"36\")");
  CHECK(readMessageEvent("ANKI_VEHICLE_MSG_V2C_VERSION_RESPONSE", "[]").error() ==
        "payload must be a JSON object, not an array");
  for (const auto& bad : testing::hostilePayloads())
    CHECK_NOTHROW(
        (void)readMessageEvent("ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE", bad.payload));
}
