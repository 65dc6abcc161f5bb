// The intents a bridge takes, in both forms, and every way one is refused
// (engine/mqtt/intents.cpp).
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

TEST_CASE("mqtt intents: the bridge subscribes to the host's and every car's intent topics") {
  // the seed's controller's filters; "…/I/#" takes "…/I" itself too
  CHECK(intentSubscriptions("pit1") ==
        std::vector<std::string>{"Anki/Host/pit1/I/#", "Anki/Car/+/I/#", "Anki/Car/I"});
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
        "no command in the payload (it is empty); name one with a key, as the seed's controller "
        "takes it — speed, lane, turn, battery, version or ping, e.g. "
        "{\"speed\":600,\"acceleration\":1000} — or with pitwall's \"type\"");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"fly"})") ==
        "unknown intent type \"fly\"; expected one of speed, lane, turn, battery, version, ping, "
        "message");
  CHECK(rejected("Anki/Car/all/I", R"({"type":7})") ==
        "\"type\" must be a string, not an integer (7)");
}

TEST_CASE("mqtt intents: host intents on the host's topic and below it, commands elsewhere") {
  const Target host{Target::Kind::Host, ""};
  for (std::string topic :
       {"Anki/Host/pit1/I", "Anki/Host/pit1/I/connection", "Anki/Host/pit1/I/anything/below"}) {
    CAPTURE(topic);
    CHECK(accepted(topic, R"({"connecting":true})") == Intent{host, ConnectIntent{true}});
    CHECK(accepted(topic, R"({"connecting":false})") == Intent{host, ConnectIntent{false}});
    CHECK(accepted(topic, R"({"cars":true})") == Intent{host, CarsIntent{}});
    CHECK(accepted(topic, R"({"car_status":true})") == Intent{host, CarStatusIntent{}});
    // anything else there is a command for every car of the host
    CHECK(accepted(topic, R"({"type":"ping"})") ==
          Intent{{Target::Kind::AllCars, ""}, PingIntent{}});
    CHECK(accepted(topic, R"({"ping":true})") == Intent{{Target::Kind::AllCars, ""}, PingIntent{}});
  }
  // a host intent on a car's topic is no command
  CHECK(rejected("Anki/Car/all/I", R"({"connecting":true})")
            .starts_with("no command in the payload (its keys: connecting)"));
  CHECK(rejected("Anki/Host/pit1/I", R"({"cars":true,"car_status":true})") ==
        "the payload names 2 host intents (cars and car_status); send one per message");
  // the track editor's bridge command: nothing pitwall does
  CHECK(rejected("Anki/Host/pit1/I", R"({"bridge":true,"host":"h","port":"1883"})") ==
        "no command in the payload (its keys: bridge, host, port); name one with a key, as the "
        "seed's controller takes it — speed, lane, turn, battery, version or ping, e.g. "
        "{\"speed\":600,\"acceleration\":1000} — or with pitwall's \"type\", or a host intent: "
        "connecting, cars or car_status");
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
  CHECK(rejected("Anki/Car/all/I", R"({"type":"lane","offset":-70.5})") ==
        "offset -70.5 mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"lane","offset":1e300})") ==
        "offset 1e+300 mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"turn","turnType":5,"trigger":0})") ==
        "turnType 5 is out of range 0..4");
  CHECK(rejected("Anki/Car/all/I", R"({"type":"turn","turnType":1,"trigger":2})") ==
        "trigger 2 is out of range 0..1");
  // the ranges are the car model's (engine/protocol/anki/limits.hpp)
  CHECK(accepted("Anki/Car/all/I", R"({"type":"speed","speed":1500,"acceleration":25000})") ==
        Intent{{Target::Kind::AllCars, ""}, SpeedIntent{1500, 25000}});
  CHECK(accepted("Anki/Car/all/I", R"({"type":"lane","offset":70})") ==
        Intent{{Target::Kind::AllCars, ""}, LaneIntent{70, {}, {}}});
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
  CHECK(rejected("Anki/Host/pit1/I/connection", R"({"connecting":"yes"})") ==
        "\"connecting\" must be true or false, not a string (\"yes\")");
  CHECK(rejected("Anki/Host/pit1/I/connection", R"({"connecting":1})") ==
        "\"connecting\" must be true or false, not an integer (1)");
}

TEST_CASE("mqtt intents: a topic outside the intent tree is rejected") {
  const std::string where =
      "not an intent topic; intents go to Anki/Host/pit1/I (or below it), Anki/Car/I, "
      "Anki/Car/all/I or Anki/Car/<car>/I (or below it)";
  CHECK(rejected("Anki/Car/" + kCar + "/E/speed", R"({"type":"ping"})") == where);
  CHECK(rejected("Anki/Car/" + kCar + "/S/I", R"({"type":"ping"})") == where);
  CHECK(rejected("Anki/Host/pit1/S/Cars", R"({"connecting":true})") == where);
  CHECK(rejected("anki/car/all/i", R"({"type":"ping"})") == where);
  CHECK(rejected("Anki/Car", R"({"type":"ping"})") == where);
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
  // the seed's controller's forms where it has one, so its bridge executes them too
  std::vector<std::string> forms{
      R"({"speed":600,"acceleration":1000})",
      R"({"lane":-23.5,"offset":-23.5,"horizontalSpeed":400,"horizontalAcceleration":4000})",
      R"({"turn":{"type":3,"time":1}})",
      R"({"battery":true})",
      R"({"version":true})",
      R"({"ping":true})",
      R"({"type":"message","frame":"021d44"})",
      R"({"type":"message","frame":"052c00004041"})",
      R"({"type":"message","frame":"0126"})",
      R"({"type":"message","frame":"06245802e80301"})"};
  for (std::size_t i = 0; i < commands.size(); ++i) {
    auto payload = intentPayload(commands[i]);
    REQUIRE(payload);
    INFO(*payload);
    CHECK(*payload == forms[i]);
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

TEST_CASE("mqtt intents: the seed's controller's forms, the key naming the command") {
  const auto one = Target{Target::Kind::Car, kCar};
  const auto all = Target{Target::Kind::AllCars, ""};
  const std::string car = "Anki/Car/" + kCar + "/I";
  // as its clients send them (hofdo/nodejsankisdk CmdHandler.js, the track editor's mqtt.js)
  CHECK(accepted(car, R"({"speed":600,"acceleration":1000})") ==
        Intent{one, SpeedIntent{600, 1000}});
  CHECK(accepted(car, R"({"acceleration":5000,"speed":600})") ==
        Intent{one, SpeedIntent{600, 5000}});
  CHECK(accepted(car, R"({"speed":600})") == Intent{one, SpeedIntent{600, 1000}});
  CHECK(accepted(car, R"({"lane":-23})") == Intent{one, LaneIntent{-23, {}, {}}});
  CHECK(accepted(car, R"({"lane":44.5,"offset":44.5})") == Intent{one, LaneIntent{44.5, {}, {}}});
  // "lane" holds the offset (the controller's current reading); "offset" when "lane" holds none
  CHECK(accepted(car, R"({"lane":-23,"offset":44.5})") == Intent{one, LaneIntent{-23, {}, {}}});
  CHECK(accepted(car, R"({"lane":true,"offset":44.5})") == Intent{one, LaneIntent{44.5, {}, {}}});
  CHECK(accepted(car, R"({"turn":{"type":3,"time":0}})") ==
        Intent{one, TurnIntent{anki::TurnType::UTurn, anki::TurnTrigger::Immediate}});
  CHECK(accepted(car, R"({"turn":{"type":1}})") ==
        Intent{one, TurnIntent{anki::TurnType::Left, anki::TurnTrigger::Immediate}});
  CHECK(accepted(car, R"({"battery":true})") == Intent{one, BatteryIntent{}});
  CHECK(accepted(car, R"({"version":true})") == Intent{one, VersionIntent{}});
  CHECK(accepted(car, R"({"ping":true})") == Intent{one, PingIntent{}});
  // the values as Node's Buffer writers take them: a string holding a number, a fraction
  CHECK(accepted(car, R"({"speed":"600","acceleration":" 1000 "})") ==
        Intent{one, SpeedIntent{600, 1000}});
  CHECK(accepted(car, R"({"lane":"-23.5"})") == Intent{one, LaneIntent{-23.5, {}, {}}});
  CHECK(accepted(car, R"({"speed":600.4})") == Intent{one, SpeedIntent{600, 1000}});
  // the topics the controller subscribes: below a car's I, and the global Anki/Car/I
  CHECK(accepted(car + "/speed", R"({"speed":300})") == Intent{one, SpeedIntent{300, 1000}});
  CHECK(accepted("Anki/Car/I", R"({"speed":0,"acceleration":12500})") ==
        Intent{all, SpeedIntent{0, 12500}});
  CHECK(accepted("Anki/Car/all/I", R"({"lane":23})") == Intent{all, LaneIntent{23, {}, {}}});
  CHECK(accepted("Anki/Host/pit1/I", R"({"speed":500})") == Intent{all, SpeedIntent{500, 1000}});
}

TEST_CASE("mqtt intents: a bad command in the controller's form names the key, value and range") {
  const std::string car = "Anki/Car/all/I";
  CHECK(rejected(car, R"({"speed":2000})") == "speed 2000 mm/s is out of range 0..1500 mm/s");
  CHECK(rejected(car, R"({"speed":"fast"})") ==
        "\"speed\" must be a number, not a string (\"fast\")");
  CHECK(rejected(car, R"({"speed":""})") == "\"speed\" must be a number, not a string (\"\")");
  CHECK(rejected(car, R"({"speed":"1e999"})") ==
        "\"speed\" must be a number, not a string (\"1e999\")");
  CHECK(rejected(car, R"({"speed":600,"acceleration":-5})") ==
        "acceleration -5 mm/s² is out of range 0..25000 mm/s²");
  CHECK(rejected(car, R"({"acceleration":1000})") ==
        "missing key \"speed\" (a number, mm/s) beside \"acceleration\"");
  CHECK(rejected(car, R"({"lane":-71})") ==
        "lane -71 mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK(rejected(car, R"({"lane":true,"offset":"x"})") ==
        "\"offset\" must be a number, not a string (\"x\")");
  CHECK(rejected(car, R"({"lane":null})") == "\"lane\" must be a number, not a null (null)");
  CHECK(rejected(car, R"({"turn":3})") ==
        "\"turn\" must be an object {\"type\":0..4,\"time\":0..1}, not an integer (3)");
  CHECK(rejected(car, R"({"turn":{"time":0}})") ==
        "missing key \"type\" in \"turn\" (0 none, 1 left, 2 right, 3 U-turn, 4 U-turn jump)");
  CHECK(rejected(car, R"({"turn":{"type":5}})") == "turn type 5 is out of range 0..4");
  CHECK(rejected(car, R"({"turn":{"type":1,"time":2}})") == "turn time 2 is out of range 0..1");
  CHECK(rejected(car, R"({"speed":600,"lane":23})") ==
        "the payload names 2 commands (speed and lane); send one command per message");
  CHECK(rejected(car, R"({"fly":true})") ==
        "no command in the payload (its keys: fly); name one with a key, as the seed's "
        "controller takes it — speed, lane, turn, battery, version or ping, e.g. "
        "{\"speed\":600,\"acceleration\":1000} — or with pitwall's \"type\"");
  // pitwall's "type" forms stay strict: integers are integers there
  CHECK(rejected(car, R"({"type":"speed","speed":"600","acceleration":1000})") ==
        "\"speed\" must be an integer, not a string (\"600\")");
}

TEST_CASE("mqtt intents: hostile values in the controller's forms are errors, never a crash") {
  for (const auto& bad : testing::hostilePayloads()) {
    for (std::string key : {"speed", "lane", "turn", "battery"}) {
      for (const auto& payload : {"{\"" + key + "\":" + bad.payload + "}",
                                  "{\"" + key + "\":{\"type\":" + bad.payload + "}}"}) {
        auto r = parseIntent("pit1", "Anki/Car/I", payload, kCars);
        if (!r) CHECK(r.error().message.size() < 2000);
      }
    }
  }
}
