#include "engine/vehicles/mqtt_topics.hpp"

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

Result<Intent, IntentError> parse(std::string_view topic, std::string_view payload) {
  return parseIntent("pit1", topic, payload, kCars);
}

// The intent a valid (topic, payload) gives; a rejection fails the test with its sentence.
Intent accepted(std::string_view topic, std::string_view payload) {
  auto r = parse(topic, payload);
  INFO(topic, " ", payload);
  if (!r) FAIL_CHECK(r.error().message);
  REQUIRE(r);
  return *r;
}

// The error sentence for an intent that must be rejected.
std::string rejected(std::string_view topic, std::string_view payload) {
  auto r = parse(topic, payload);
  REQUIRE_FALSE(r);
  CHECK(r.error().topic == topic);
  return r.error().message;
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
              });
}

TEST_CASE("mqtt topics: an intersection update gives its code and distances") {
  anki::IntersectionUpdate m;
  m.intersection_code = 3;
  m.mm_since_last_transition_bar = 120;
  m.mm_since_last_intersection_code = 450;
  CHECK(fromMessage(kCar, m, std::nullopt, kNow) ==
        std::vector<Publication>{ev("intersection_code", "3"),
                                 ev("mm_since_last_transition_bar", "120"),
                                 ev("mm_since_last_intersection_code", "450")});
  SUBCASE("the older layout has no distance since the last code, so none is published") {
    m.mm_since_last_intersection_code.reset();
    CHECK(fromMessage(kCar, m, std::nullopt, kNow).size() == 2);
  }
}

TEST_CASE("mqtt topics: delocalized is an event with the timestamp only") {
  CHECK(fromMessage(kCar, anki::Delocalized{}, std::nullopt, kNow) ==
        std::vector<Publication>{
            {"Anki/Car/" + kCar + "/E/Delocalized", "{\"timestamp\":1700000000123}", 0, false}});
}

TEST_CASE("mqtt topics: replies and reports become retained status") {
  CHECK(fromMessage(kCar, anki::VersionResponse{0x2b6e}, std::nullopt, kNow) ==
        std::vector<Publication>{st("Version", "11118")});
  CHECK(fromMessage(kCar, anki::BatteryResponse{3912}, std::nullopt, kNow) ==
        std::vector<Publication>{st("BatteryLevel", "3912")});
  CHECK(fromMessage(kCar, anki::OffsetUpdate{-68.0f, 1}, std::nullopt, kNow) ==
        std::vector<Publication>{st("Lane/Actual", "-68.0")});
  CHECK(fromMessage(kCar, anki::SpeedUpdate{600, 1000, 598}, std::nullopt, kNow) ==
        std::vector<Publication>{st("Speed/Actual", "598")});
  anki::CarStatus status;
  status.on_track = true;
  status.on_charger = false;
  CHECK(fromMessage(kCar, status, std::nullopt, kNow) ==
        std::vector<Publication>{
            {"Anki/Car/" + kCar + "/S/CarStatus",
             R"({"timestamp":1700000000123,"online":true,"charging":false,"onTrack":true})", 1,
             true}});
}

TEST_CASE("mqtt topics: a ping response carries the round-trip time in ms, or null") {
  CHECK(fromMessage(kCar, anki::PingResponse{}, 0.0125, kNow) ==
        std::vector<Publication>{{"Anki/Car/" + kCar + "/S/PingResponse",
                                  R"({"timestamp":1700000000123,"rtt_ms":12.5})", 1, true}});
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
  CarInfo info{kCar, "E8:5A:0F:11:22:33", 0x12345678, 9, 0xBEEF, "skull"};
  CarState state;
  state.on_charger = true;
  auto ps = carJoined(info, state, kNow);
  CHECK(
      ps ==
      std::vector<Publication>{
          {"Anki/Car/" + kCar + "/S/Information",
           R"({"address":"E8:5A:0F:11:22:33","identifier":305419896,"model":"Skull",)"
           R"("modelId":9,"productId":48879,"name":"skull"})",
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
  CHECK(hostCars("pit1", kCars, kNow) ==
        Publication{"Anki/Host/pit1/S/Cars",
                    R"({"timestamp":1700000000123,"value":["e85a0f112233","sim-0000002a"]})", 1,
                    true});
  CHECK(hostCars("pit1", {}, kNow).payload == R"({"timestamp":1700000000123,"value":[]})");
  CHECK(carDiscovered("pit1", kCar, kNow) ==
        Publication{"Anki/Host/pit1/E/CarDiscovered",
                    R"({"timestamp":1700000000123,"Car":"e85a0f112233"})", 0, false});
}

TEST_CASE("mqtt intents: the bridge subscribes to the host's and every car's intent topics") {
  CHECK(intentSubscriptions("pit1") == std::vector<std::string>{"Anki/Host/pit1/I/connection",
                                                                "Anki/Host/pit1/I",
                                                                "Anki/Car/+/I"});
}

TEST_CASE("mqtt intents: every intent type is parsed with its target") {
  auto one = Target{Target::Kind::Car, kCar};
  auto all = Target{Target::Kind::AllCars, ""};
  const std::string carTopic = "Anki/Car/" + kCar + "/I";
  CHECK(accepted("Anki/Host/pit1/I/connection", R"({"connecting":true})") ==
        Intent{{Target::Kind::Host, ""}, ConnectIntent{true}});
  CHECK(accepted("Anki/Host/pit1/I/connection", R"({"connecting":false})") ==
        Intent{{Target::Kind::Host, ""}, ConnectIntent{false}});
  CHECK(accepted(carTopic, R"({"type":"speed","speed":600,"acceleration":1000})") ==
        Intent{one, SpeedIntent{600, 1000}});
  CHECK(accepted(carTopic, R"({"type":"lane","offset":-23})") ==
        Intent{one, LaneIntent{-23, {}, {}}});
  CHECK(accepted(carTopic, R"({"type":"lane","offset":44.5})") ==
        Intent{one, LaneIntent{44.5, {}, {}}});
  CHECK(accepted(carTopic, R"({"type":"turn","turnType":3,"trigger":0})") ==
        Intent{one, TurnIntent{anki::TurnType::UTurn, anki::TurnTrigger::Immediate}});
  CHECK(accepted(carTopic, R"({"type":"battery"})") == Intent{one, BatteryIntent{}});
  CHECK(accepted(carTopic, R"({"type":"version"})") == Intent{one, VersionIntent{}});
  CHECK(accepted(carTopic, R"({"type":"ping"})") == Intent{one, PingIntent{}});
  CHECK(accepted("Anki/Car/all/I", R"({"type":"speed","speed":0,"acceleration":25000})") ==
        Intent{all, SpeedIntent{0, 25000}});
  CHECK(accepted("Anki/Host/pit1/I", R"({"type":"turn","turnType":1,"trigger":1})") ==
        Intent{all, TurnIntent{anki::TurnType::Left, anki::TurnTrigger::Intersection}});
  CHECK(accepted("Anki/Car/sim-0000002a/I", R"({"type":"ping","extra":1})") ==
        Intent{{Target::Kind::Car, "sim-0000002a"}, PingIntent{}});
}

TEST_CASE("mqtt intents: bad JSON is rejected with the parser's message") {
  auto e = rejected("Anki/Car/all/I", R"({"type":"speed",)");
  CHECK(e.starts_with("payload is not JSON: [json.exception.parse_error.101]"));
  CHECK(rejected("Anki/Car/all/I", "").starts_with("payload is not JSON:"));
  CHECK(rejected("Anki/Car/all/I", "[1,2]") ==
        "payload must be a JSON object, not an array ([1,2])");
}

TEST_CASE("mqtt intents: a missing or unknown type is rejected with the accepted types") {
  CHECK(rejected("Anki/Car/all/I", "{}") ==
        "missing key \"type\" (one of speed, lane, turn, battery, version, ping, message)");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"fly"})") ==
        "unknown intent type \"fly\"; expected one of speed, lane, turn, battery, version, ping, "
        "message");
  CHECK(rejected("Anki/Car/all/I", R"({"type":7})") ==
        "\"type\" must be a string, not an integer (7)");
}

TEST_CASE("mqtt intents: a connection intent is only accepted on the host's connection topic") {
  CHECK(rejected("Anki/Host/pit1/I", R"({"connecting":true})") ==
        "missing key \"type\" (one of speed, lane, turn, battery, version, ping, message)");
  CHECK(rejected("Anki/Host/pit1/I/connection", R"({"type":"ping"})") ==
        "missing key \"connecting\" (true or false)");
}

TEST_CASE("mqtt intents: an intent for a car this host does not have is rejected") {
  CHECK(rejected("Anki/Car/ffffffffffff/I", R"({"type":"ping"})") ==
        "unknown car \"ffffffffffff\"; known cars: e85a0f112233, sim-0000002a (or \"all\")");
  auto none = parseIntent("pit1", "Anki/Car/x/I", R"({"type":"ping"})", {});
  REQUIRE_FALSE(none);
  CHECK(none.error().message == "unknown car \"x\"; known cars: none (or \"all\")");
}

TEST_CASE("mqtt intents: every out-of-range value is rejected with the car model's range") {
  CHECK(rejected("Anki/Car/all/I", R"({"type":"speed","speed":2000,"acceleration":1000})") ==
        "speed 2000 mm/s is out of range 0..1500 mm/s");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"speed","speed":-1,"acceleration":1000})") ==
        "speed -1 mm/s is out of range 0..1500 mm/s");
  CHECK(rejected("Anki/Car/all/I",
                 R"({"type":"speed","speed":600,"acceleration":18446744073709551615})") ==
        "acceleration 18446744073709551615 mm/s² is out of range 0..25000 mm/s²");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"lane","offset":-100.5})") ==
        "offset -100.5 mm is out of range -100..100 mm");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"lane","offset":1e300})") ==
        "offset 1e+300 mm is out of range -100..100 mm");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"turn","turnType":5,"trigger":0})") ==
        "turnType 5 is out of range 0..4");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"turn","turnType":1,"trigger":2})") ==
        "trigger 2 is out of range 0..1");
  // the ranges are the car model's (engine/protocol/anki/limits.hpp)
  CHECK(accepted("Anki/Car/all/I", R"({"type":"speed","speed":1500,"acceleration":25000})") ==
        Intent{{Target::Kind::AllCars, ""}, SpeedIntent{1500, 25000}});
  CHECK(accepted("Anki/Car/all/I", R"({"type":"lane","offset":100})") ==
        Intent{{Target::Kind::AllCars, ""}, LaneIntent{100, {}, {}}});
  CHECK(accepted("Anki/Car/all/I", R"({"type":"turn","turnType":4,"trigger":1})") ==
        Intent{{Target::Kind::AllCars, ""},
               TurnIntent{anki::TurnType::UTurnJump, anki::TurnTrigger::Intersection}});
}

TEST_CASE("mqtt intents: missing and wrong-typed keys are named") {
  CHECK(rejected("Anki/Car/all/I", R"({"type":"speed","acceleration":1000})") ==
        "missing key \"speed\" (an integer)");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"speed","speed":600})") ==
        "missing key \"acceleration\" (an integer)");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"speed","speed":"600","acceleration":1000})") ==
        "\"speed\" must be an integer, not a string (\"600\")");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"speed","speed":600.5,"acceleration":1000})") ==
        "\"speed\" must be an integer, not a number (600.5)");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"lane"})") ==
        "missing key \"offset\" (a number, mm from road centre)");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"lane","offset":null})") ==
        "\"offset\" must be a number, not a null (null)");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"turn","trigger":0})") ==
        "missing key \"turnType\" (an integer)");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"turn","turnType":true,"trigger":0})") ==
        "\"turnType\" must be an integer, not a boolean (true)");
  CHECK(rejected("Anki/Host/pit1/I/connection", "{}") ==
        "missing key \"connecting\" (true or false)");
  CHECK(rejected("Anki/Host/pit1/I/connection", R"({"connecting":"yes"})") ==
        "\"connecting\" must be true or false, not a string (\"yes\")");
  CHECK(rejected("Anki/Host/pit1/I/connection", R"({"connecting":1})") ==
        "\"connecting\" must be true or false, not an integer (1)");
}

TEST_CASE("mqtt intents: a topic outside the intent tree is rejected") {
  const std::string where =
      "not an intent topic; intents go to Anki/Host/pit1/I/connection, Anki/Host/pit1/I, "
      "Anki/Car/all/I or Anki/Car/<car>/I";
  CHECK(rejected("Anki/Car/" + kCar + "/E/speed", R"({"type":"ping"})") == where);
  CHECK(rejected("Anki/Car/" + kCar + "/I/extra", R"({"type":"ping"})") == where);
  CHECK(rejected("Anki/Host/pit1/I/other", R"({"connecting":true})") == where);
  CHECK(rejected("anki/car/all/i", R"({"type":"ping"})") == where);
  CHECK(rejected("", "{}") == where);
  CHECK(rejected("Anki/Host/pit2/I", R"({"type":"ping"})") ==
        "intent addressed to host \"pit2\", this host is \"pit1\"");
  CHECK(rejected("Anki/Host/pit2/I/connection", R"({"connecting":true})") ==
        "intent addressed to host \"pit2\", this host is \"pit1\"");
}

TEST_CASE("mqtt intents: a rejected intent is answered on the host's IntentError topic") {
  auto r = parse("Anki/Car/all/I", R"({"type":"speed","speed":2000,"acceleration":1000})");
  REQUIRE_FALSE(r);
  CHECK(intentError("pit1", r.error(), kNow) ==
        Publication{"Anki/Host/pit1/S/IntentError",
                    R"({"timestamp":1700000000123,"topic":"Anki/Car/all/I",)"
                    R"("error":"speed 2000 mm/s is out of range 0..1500 mm/s"})",
                    1, false});
  // a message that needs escaping stays valid JSON
  auto bad = parse("Anki/Car/all/I", "{\"type\":\"\\\"\"}");
  REQUIRE_FALSE(bad);
  CHECK(intentError("pit1", bad.error(), kNow).payload ==
        R"({"timestamp":1700000000123,"topic":"Anki/Car/all/I","error":"unknown intent type )"
        R"(\"\\\"\"; expected one of speed, lane, turn, battery, version, ping, message"})");
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

TEST_CASE(
    "mqtt intents: a lane intent takes pitwall's optional horizontal speed and acceleration") {
  Target one{Target::Kind::Car, kCar};
  CHECK(
      accepted(
          "Anki/Car/" + kCar + "/I",
          R"({"type":"lane","offset":-23,"horizontalSpeed":400,"horizontalAcceleration":4000})") ==
      Intent{one, LaneIntent{-23, 400, 4000}});
  CHECK(rejected("Anki/Car/all/I", R"({"type":"lane","offset":0,"horizontalSpeed":1501})") ==
        "horizontalSpeed 1501 mm/s is out of range 0..1500 mm/s");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"lane","offset":0,"horizontalAcceleration":"x"})") ==
        "\"horizontalAcceleration\" must be an integer, not a string (\"x\")");
}

TEST_CASE("mqtt intents: a message intent carries any command frame, checked like the others") {
  Target all{Target::Kind::AllCars, ""};
  // set-lights 0x44 (anki-overdrive.md): frame 02 1d 44
  auto lights = accepted("Anki/Car/all/I", R"({"type":"message","frame":"021d44"})");
  CHECK(lights ==
        Intent{all,
               MessageIntent{anki::decode(std::vector<std::uint8_t>{0x02, 0x1d, 0x44}).value()}});
  CHECK(rejected("Anki/Car/all/I", R"({"type":"message"})") ==
        "missing key \"frame\" (a string of hex digits)");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"message","frame":12})") ==
        "\"frame\" must be a string of hex digits, not an integer (12)");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"message","frame":"021"})") ==
        "\"frame\": odd number of hex digits (3)");
  // a report the car sends (version response) is not a command
  CHECK(rejected("Anki/Car/all/I", R"({"type":"message","frame":"03196e2b"})") ==
        "\"frame\" holds version-response, which a car sends; only controller→vehicle messages "
        "can be sent");
  // set-speed 2000 mm/s through a frame: the same range check as the speed intent
  CHECK(rejected("Anki/Car/all/I", R"({"type":"message","frame":"0624d007e80300"})") ==
        "speed 2000 mm/s is out of range 0..1500 mm/s");
  // a frame whose size byte disagrees with its length
  CHECK(rejected("Anki/Car/all/I", R"({"type":"message","frame":"0524d007"})")
            .starts_with("\"frame\": "));
}

TEST_CASE("mqtt intents: a remote command becomes the intent that parses back to it") {
  using anki::Message;
  std::vector<Message> commands{
      anki::SetSpeed{600, 1000, false},
      anki::ChangeLane{400, 4000, -23.5f, 0, 0},
      anki::Turn{anki::TurnType::UTurn, anki::TurnTrigger::Intersection},
      anki::BatteryRequest{},
      anki::VersionRequest{},
      anki::PingRequest{},
      anki::SetLights{0x44},
      anki::SetOffset{12.0f},
      anki::CancelLaneChange{},
      anki::SetSpeed{600, 1000, true},  // respect_limit has no key in the seed's speed intent
  };
  std::vector<std::string> types{"speed", "lane",    "turn",    "battery", "version",
                                 "ping",  "message", "message", "message", "message"};
  for (std::size_t i = 0; i < commands.size(); ++i) {
    auto payload = intentPayload(commands[i]);
    REQUIRE(payload);
    INFO(*payload);
    CHECK(payload->find("\"type\":\"" + types[i] + "\"") != std::string::npos);
    auto intent = accepted("Anki/Car/" + kCar + "/I", *payload);
    // executed as the bridge does: the action must describe the same command
    std::visit(
        [&](const auto& a) {
          using A = std::decay_t<decltype(a)>;
          if constexpr (std::is_same_v<A, MessageIntent>) {
            CHECK(a.message == commands[i]);
          } else if constexpr (std::is_same_v<A, SpeedIntent>) {
            CHECK(Message{anki::SetSpeed{static_cast<std::int16_t>(a.speed_mm_s),
                                         static_cast<std::int16_t>(a.accel_mm_s2), false}} ==
                  commands[i]);
          } else if constexpr (std::is_same_v<A, LaneIntent>) {
            CHECK(Message{anki::ChangeLane{static_cast<std::uint16_t>(*a.h_speed_mm_s),
                                           static_cast<std::uint16_t>(*a.h_accel_mm_s2),
                                           static_cast<float>(a.offset_mm), 0, 0}} == commands[i]);
          } else if constexpr (std::is_same_v<A, TurnIntent>) {
            CHECK(Message{anki::Turn{a.type, a.trigger}} == commands[i]);
          } else if constexpr (std::is_same_v<A, BatteryIntent>) {
            CHECK(Message{anki::BatteryRequest{}} == commands[i]);
          } else if constexpr (std::is_same_v<A, VersionIntent>) {
            CHECK(Message{anki::VersionRequest{}} == commands[i]);
          } else if constexpr (std::is_same_v<A, PingIntent>) {
            CHECK(Message{anki::PingRequest{}} == commands[i]);
          } else {
            FAIL("a command became a connection intent");
          }
        },
        intent.action);
  }
  CHECK_FALSE(intentPayload(anki::VersionResponse{0x2b6e}));  // a report, not a command
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

  CarInfo info{kCar, "E8:5A:0F:11:22:33", 0x12345678, 9, 0xBEEF, "skull"};
  auto joined = carJoined(info, CarState{}, kNow);
  auto read = readInformation(kCar, joined[0].payload);
  REQUIRE(read);
  CHECK(read->name == "skull");
  CHECK(read->identifier == 0x12345678u);
  CHECK(read->model_id == 9);
  CHECK(read->address == "E8:5A:0F:11:22:33");
  // the seed's payload, without pitwall's name
  auto seed =
      readInformation(kCar, R"({"address":"a","identifier":1,"model":"Skull","modelId":9})");
  REQUIRE(seed);
  CHECK(seed->name.empty());
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
  CHECK(*readHostCars(hostCars("pit1", cars, kNow).payload) == cars);
  CHECK(readHostCars(R"({"value":[1]})").error() == "\"value\" has the wrong type ([1])");
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

TEST_CASE("mqtt intents: a hostile payload is an error that quotes at most 80 bytes, escaped") {
  for (const auto& bad : pitwall::testing::hostilePayloads()) {
    CAPTURE(bad.name);
    auto e = rejected("Anki/Car/all/I", bad.payload);
    CAPTURE(e);
    CHECK(e.find(bad.error) != std::string::npos);
    CHECK(e.size() < 600);
    // the answer is valid JSON within its bound, whatever the payload held
    auto answer = intentError("pit1", IntentError{"Anki/Car/all/I", e}, kNow).payload;
    CHECK(answer.size() <= kMaxIntentError);
    CHECK(nlohmann::json::parse(answer)["error"] == e);
  }
  CHECK(rejected("Anki/Car/all/I", "5e999") ==
        "payload holds a number beyond the range of a double: [json.exception.out_of_range.406] "
        "number overflow parsing '5e999'; send numbers within ±1.7e308 (and within the ranges of "
        "the intent)");
  CHECK(rejected("Anki/Car/all/I", "{\"type\":\"fly\xff\"}")
            .ends_with("ill-formed UTF-8 byte; last read: '\"fly\\xff'"));
  // The token nlohmann quotes is cut to its last 80 bytes.
  auto longToken = rejected("Anki/Car/all/I", "{\"type\":\"" + std::string(60000, 'a') + "\x01");
  // (nlohmann shows a control character as <U+0001> itself)
  CHECK(longToken.find("last read: '…" + std::string(72, 'a') + "<U+0001>'") != std::string::npos);
  CHECK(rejected("Anki/Car/all/I", std::string(70000, ' ')) ==
        "payload is 70000 bytes, more than 65536 (it begins " + std::string(80, ' ') +
            "…); send a smaller payload, or raise the limit with --mqtt-max-payload");
  CHECK(rejected("Anki/Car/all/I", pitwall::testing::nested(65, "")) ==
        "payload nests objects and arrays more than 64 deep (it begins " + std::string(65, '[') +
            std::string(15, ']') + "…); send flatter JSON");
  // up to the limits: accepted
  CHECK(accepted("Anki/Car/all/I", pitwall::testing::deepSpeedIntent(64)).action ==
        Action{SpeedIntent{600, 1000}});
  CHECK(accepted("Anki/Car/all/I", pitwall::testing::paddedSpeedIntent(64 * 1024)).action ==
        Action{SpeedIntent{600, 1000}});
  // and the limits are the caller's
  CHECK(parseIntent("pit1", "Anki/Car/all/I", pitwall::testing::paddedSpeedIntent(2000), kCars,
                    PayloadLimits{1999, 64})
            .error()
            .message.starts_with("payload is 2000 bytes, more than 1999"));
  CHECK(parseIntent("pit1", "Anki/Car/all/I", pitwall::testing::deepSpeedIntent(3), kCars,
                    PayloadLimits{kDefaultMaxPayload, 2})
            .error()
            .message.starts_with("payload nests objects and arrays more than 2 deep"));
}

TEST_CASE("mqtt intents: an error about a hostile topic quotes it short and escaped") {
  std::string car(5000, 'c');
  auto e = rejected("Anki/Car/" + car + "/I", R"({"type":"ping"})");
  CHECK(e.starts_with("unknown car \"" + std::string(80, 'c') + "…\"; known cars: "));
  auto answer =
      intentError("pit1", IntentError{std::string(60000, '\xff'), std::string(60000, '"')}, kNow);
  CHECK(answer.payload.size() <= kMaxIntentError);
  CHECK(nlohmann::json::parse(answer.payload).is_object());
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
