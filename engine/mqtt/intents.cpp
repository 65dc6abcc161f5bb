// The seed's MQTT topic tree, broker → intents: which topics a bridge takes, the intent forms
// (the seed's controller's, where the key names the command, and pitwall's "type" forms),
// checked against engine/protocol/anki/limits.hpp; the answer to a refused one; and the intent
// a remote car publishes for a command.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <tuple>

#include "engine/core/hex.hpp"
#include "engine/core/numbers.hpp"
#include "engine/core/overload.hpp"
#include "engine/mqtt/payload.hpp"
#include "engine/mqtt/topics.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "engine/protocol/anki/limits.hpp"

namespace pitwall::topics {
using namespace detail;

namespace {

template <typename T, std::size_t I = 0>
constexpr std::size_t variantIndex() {
  if constexpr (std::is_same_v<std::variant_alternative_t<I, anki::Message>, T>)
    return I;
  else
    return variantIndex<T, I + 1>();
}

bool isCommand(const anki::Message& m) {
  return m.index() <= variantIndex<anki::SdkMode>();
}

}  // namespace

// ---- broker → intents ----

std::vector<std::string> intentSubscriptions(std::string_view host) {
  // As the seed's controller subscribes: "a/I/#" matches "a/I" itself too
  return {hostTopic(host, "I/#"), "Anki/Car/+/I/#", "Anki/Car/I"};
}

namespace {

using Parsed = Result<Action, std::string>;

// The key, present and of the right kind; otherwise the sentence saying why not.
Result<const In*, std::string> field(const In& j, const char* key, const char* kind) {
  auto it = j.find(key);
  if (it == j.end()) return Unexpected{std::string("missing key \"") + key + "\" (" + kind + ")"};
  return &*it;
}

// An integer within [lo, hi], checked as a double so that 1e30 or 2^64 cannot wrap.
Result<int, std::string> integer(const In& j, const char* key, int lo, int hi,
                                 std::string_view unit) {
  auto f = field(j, key, "an integer");
  if (!f) return Unexpected{f.error()};
  const In& v = **f;
  if (!v.is_number_integer())
    return Unexpected{std::string("\"") + key + "\" must be an integer, not " + typeName(v) + " (" +
                      excerpt(v) + ")"};
  double d = v.get<double>();
  if (d < lo || d > hi) return Unexpected{outOfRange(key, v.dump(), lo, hi, unit)};
  return static_cast<int>(d);
}

// ---- the seed's controller's forms: the key names the command ----
//
// {"speed":600,"acceleration":1000}, {"lane":-23} (or {"lane":…,"offset":-23}),
// {"turn":{"type":3,"time":0}}, {"battery":true}, {"version":true}, {"ping":true}
// (../shared/protocols/mqtt-topics.md). The controller hands the values to Node's Buffer
// writers, which take a number or a string holding one: so do these.

// A number, or a string holding one ("600", as a form field gives it); nullopt with the
// sentence when neither.
Result<double, std::string> looseNumber(const In& v, std::string_view key) {
  if (v.is_number()) return v.get<double>();
  if (v.is_string()) {
    const auto& text = v.get_ref<const std::string&>();
    auto first = text.find_first_not_of(" \t");
    auto last = text.find_last_not_of(" \t");
    if (first != std::string::npos) {
      std::string_view digits(text.data() + first, last - first + 1);
      double d = 0;
      auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), d);
      if (ec == std::errc{} && end == digits.data() + digits.size() && std::isfinite(d)) return d;
    }
  }
  return Unexpected{"\"" + std::string(key) + "\" must be a number, not " + typeName(v) + " (" +
                    excerpt(v) + ")"};
}

// The number at `key` rounded to an integer within [lo, hi].
Result<int, std::string> looseInteger(const In& v, std::string_view key, int lo, int hi,
                                      std::string_view unit) {
  auto d = looseNumber(v, key);
  if (!d) return Unexpected{d.error()};
  double r = std::round(*d);
  if (!(r >= lo && r <= hi)) return Unexpected{outOfRange(key, excerpt(v), lo, hi, unit)};
  return static_cast<int>(r);
}

Result<double, std::string> offsetValue(const In& v, std::string_view key) {
  namespace L = anki::limits;
  auto d = looseNumber(v, key);
  if (!d) return Unexpected{d.error()};
  if (!(*d >= L::kOffsetMin && *d <= L::kOffsetMax))
    return Unexpected{outOfRange(key, excerpt(v), L::kOffsetMin, L::kOffsetMax, "mm") +
                      " (beyond it the car leaves the road)"};
  return *d;
}

Parsed speedIntent(const In& j) {
  namespace L = anki::limits;
  auto speed = integer(j, "speed", L::kSpeedMin, L::kSpeedMax, "mm/s");
  if (!speed) return Unexpected{speed.error()};
  auto accel = integer(j, "acceleration", L::kAccelMin, L::kAccelMax, "mm/s²");
  if (!accel) return Unexpected{accel.error()};
  return Action{SpeedIntent{*speed, *accel}};
}

Parsed laneIntent(const In& j) {
  namespace L = anki::limits;
  auto f = field(j, "offset", "a number, mm from road centre");
  if (!f) return Unexpected{f.error()};
  const In& v = **f;
  if (!v.is_number())
    return Unexpected{"\"offset\" must be a number, not " + typeName(v) + " (" + excerpt(v) + ")"};
  auto d = offsetValue(v, "offset");
  if (!d) return Unexpected{d.error()};
  LaneIntent lane;
  lane.offset_mm = *d;
  if (j.contains("horizontalSpeed")) {
    auto v = integer(j, "horizontalSpeed", L::kLaneSpeedMin, L::kLaneSpeedMax, "mm/s");
    if (!v) return Unexpected{v.error()};
    lane.h_speed_mm_s = *v;
  }
  if (j.contains("horizontalAcceleration")) {
    auto v = integer(j, "horizontalAcceleration", L::kLaneAccelMin, L::kLaneAccelMax, "mm/s²");
    if (!v) return Unexpected{v.error()};
    lane.h_accel_mm_s2 = *v;
  }
  return Action{lane};
}

Parsed messageIntent(const In& j) {
  auto f = field(j, "frame", "a string of hex digits");
  if (!f) return Unexpected{f.error()};
  const In& v = **f;
  if (!v.is_string())
    return Unexpected{"\"frame\" must be a string of hex digits, not " + typeName(v) + " (" +
                      excerpt(v) + ")"};
  auto bytes = fromHex(v.get_ref<const std::string&>());
  if (!bytes) return Unexpected{"\"frame\": " + quote(bytes.error())};
  auto message = anki::decode(*bytes);
  if (!message) return Unexpected{"\"frame\": " + message.error().message()};
  if (!isCommand(*message))
    return Unexpected{"\"frame\" holds " + std::string(anki::name(*message)) +
                      ", which a car sends; only controller→vehicle messages can be sent"};
  if (auto problem = anki::limits::validate(*message)) return Unexpected{*problem};
  return Action{MessageIntent{std::move(*message)}};
}

Parsed turnIntent(const In& j) {
  // anki-overdrive.md: type 0 none … 4 U-turn jump; trigger 0 immediate, 1 at next intersection
  auto type = integer(j, "turnType", 0, static_cast<int>(anki::TurnType::UTurnJump), "");
  if (!type) return Unexpected{type.error()};
  auto trigger = integer(j, "trigger", 0, static_cast<int>(anki::TurnTrigger::Intersection), "");
  if (!trigger) return Unexpected{trigger.error()};
  return Action{
      TurnIntent{static_cast<anki::TurnType>(*type), static_cast<anki::TurnTrigger>(*trigger)}};
}

Parsed commandIntent(const In& j) {
  auto f = field(j, "type", "one of speed, lane, turn, battery, version, ping, message");
  if (!f) return Unexpected{f.error()};
  const In& t = **f;
  if (!t.is_string())
    return Unexpected{"\"type\" must be a string, not " + typeName(t) + " (" + excerpt(t) + ")"};
  const auto& type = t.get_ref<const std::string&>();
  if (type == "speed") return speedIntent(j);
  if (type == "lane") return laneIntent(j);
  if (type == "turn") return turnIntent(j);
  if (type == "battery") return Action{BatteryIntent{}};
  if (type == "version") return Action{VersionIntent{}};
  if (type == "ping") return Action{PingIntent{}};
  if (type == "message") return messageIntent(j);
  return Unexpected{"unknown intent type " + excerpt(t) +
                    "; expected one of speed, lane, turn, battery, version, ping, message"};
}

// The command keys of the controller's forms, in the order error sentences list them.
constexpr std::array<const char*, 6> kCommandKeys{"speed",   "lane",    "turn",
                                                  "battery", "version", "ping"};
constexpr const char* kCommandKeyList = "speed, lane, turn, battery, version or ping";

Parsed keyedSpeed(const In& j) {
  namespace L = anki::limits;
  auto it = j.find("speed");
  if (it == j.end())
    return Unexpected{
        std::string("missing key \"speed\" (a number, mm/s) beside \"acceleration\"")};
  auto speed = looseInteger(*it, "speed", L::kSpeedMin, L::kSpeedMax, "mm/s");
  if (!speed) return Unexpected{speed.error()};
  int accel = kDefaultAccel;  // what the controller's clients send (their STANDARD_ACCELERATION)
  if (auto a = j.find("acceleration"); a != j.end()) {
    auto v = looseInteger(*a, "acceleration", L::kAccelMin, L::kAccelMax, "mm/s²");
    if (!v) return Unexpected{v.error()};
    accel = *v;
  }
  return Action{SpeedIntent{*speed, accel}};
}

Parsed keyedLane(const In& j) {
  namespace L = anki::limits;
  // The controller's current CmdHandler reads the offset from "lane" itself (an earlier one read
  // "offset", and some clients send both): "lane" when it holds a number, else "offset".
  auto it = j.find("lane");
  const char* key = "lane";
  if (auto offset = j.find("offset"); offset != j.end() && !looseNumber(*it, key)) {
    it = offset;
    key = "offset";
  }
  auto offset = offsetValue(*it, key);
  if (!offset) return Unexpected{offset.error()};
  LaneIntent lane;
  lane.offset_mm = *offset;
  for (auto [name, out, lo, hi, unit] : {std::tuple{"horizontalSpeed", &lane.h_speed_mm_s,
                                                    L::kLaneSpeedMin, L::kLaneSpeedMax, "mm/s"},
                                         std::tuple{"horizontalAcceleration", &lane.h_accel_mm_s2,
                                                    L::kLaneAccelMin, L::kLaneAccelMax, "mm/s²"}}) {
    if (auto v = j.find(name); v != j.end()) {
      auto n = looseInteger(*v, name, lo, hi, unit);
      if (!n) return Unexpected{n.error()};
      *out = *n;
    }
  }
  return Action{lane};
}

Parsed keyedTurn(const In& j) {
  const In& t = j.at("turn");
  if (!t.is_object())
    return Unexpected{"\"turn\" must be an object {\"type\":0..4,\"time\":0..1}, not " +
                      typeName(t) + " (" + excerpt(t) + ")"};
  auto type = t.find("type");
  if (type == t.end())
    return Unexpected{
        std::string("missing key \"type\" in \"turn\" (0 none, 1 left, 2 right, 3 "
                    "U-turn, 4 U-turn jump)")};
  auto kind = looseInteger(*type, "turn type", 0, static_cast<int>(anki::TurnType::UTurnJump), "");
  if (!kind) return Unexpected{kind.error()};
  int trigger = 0;  // the controller writes a missing "time" as 0: now
  if (auto time = t.find("time"); time != t.end()) {
    auto v =
        looseInteger(*time, "turn time", 0, static_cast<int>(anki::TurnTrigger::Intersection), "");
    if (!v) return Unexpected{v.error()};
    trigger = *v;
  }
  return Action{
      TurnIntent{static_cast<anki::TurnType>(*kind), static_cast<anki::TurnTrigger>(trigger)}};
}

// A command in the controller's form; `also` is what else the topic takes, for the sentence
// when the payload names no command.
Parsed keyedCommand(const In& j, std::string_view also) {
  std::vector<std::string> named;
  for (const char* key : kCommandKeys)
    if (j.contains(key)) named.emplace_back(key);
  if (named.empty() && j.contains("acceleration")) named.emplace_back("speed");
  if (named.empty()) {
    std::string keys;
    for (const auto& [key, value] : j.items()) {
      if (keys.size() > 60) {
        keys += ", …";
        break;
      }
      keys += (keys.empty() ? "" : ", ") + quote(key, 32);
    }
    return Unexpected{"no command in the payload" +
                      (keys.empty() ? std::string(" (it is empty)") : " (its keys: " + keys + ")") +
                      "; name one with a key, as the seed's controller takes it — " +
                      kCommandKeyList +
                      ", e.g. {\"speed\":600,\"acceleration\":1000} — or with pitwall's \"type\"" +
                      std::string(also)};
  }
  if (named.size() > 1) {
    std::string list;
    for (const auto& n : named) list += (list.empty() ? "" : " and ") + n;
    return Unexpected{"the payload names " + std::to_string(named.size()) + " commands (" + list +
                      "); send one command per message"};
  }
  const std::string& command = named.front();
  if (command == "speed") return keyedSpeed(j);
  if (command == "lane") return keyedLane(j);
  if (command == "turn") return keyedTurn(j);
  // the controller sends these whatever the value is
  if (command == "battery") return Action{BatteryIntent{}};
  if (command == "version") return Action{VersionIntent{}};
  return Action{PingIntent{}};
}

Parsed carCommand(const In& j, std::string_view also = "") {
  if (j.contains("type")) return commandIntent(j);
  return keyedCommand(j, also);
}

// On Anki/Host/<host>/I…: a host intent, or else a command for every car of the host.
Parsed hostIntent(const In& j) {
  std::vector<std::string> named;
  for (const char* key : {"connecting", "cars", "car_status"})
    if (j.contains(key)) named.emplace_back(key);
  if (named.size() > 1)
    return Unexpected{"the payload names " + std::to_string(named.size()) + " host intents (" +
                      named[0] + " and " + named[1] + "); send one per message"};
  if (named.empty()) {
    if (j.contains("type")) return commandIntent(j);
    return keyedCommand(j, ", or a host intent: connecting, cars or car_status");
  }
  if (named[0] == "cars") return Action{CarsIntent{}};
  if (named[0] == "car_status") return Action{CarStatusIntent{}};
  const In& v = j.at("connecting");
  if (!v.is_boolean())
    return Unexpected{"\"connecting\" must be true or false, not " + typeName(v) + " (" +
                      excerpt(v) + ")"};
  return Action{ConnectIntent{v.get<bool>()}};
}
}  // namespace

Result<Intent, IntentError> parseIntent(std::string_view host, std::string_view topic,
                                        std::string_view payload,
                                        std::span<const std::string> knownCars,
                                        const PayloadLimits& limits) {
  auto fail = [&](std::string message) {
    return Unexpected{IntentError{std::string(topic), std::move(message)}};
  };
  // Which intent the topic names: the seed's controller's filters Anki/Host/<host>/I/#,
  // Anki/Car/+/I/# and Anki/Car/I.
  auto parts = split(topic);
  const bool anki = parts.size() >= 3 && parts[0] == "Anki";
  Target target;
  bool onHost = false;
  if (anki && parts[1] == "Host" && parts.size() >= 4 && parts[3] == "I") {
    if (parts[2] != host)
      return fail("intent addressed to host \"" + quote(parts[2]) + "\", this host is \"" +
                  std::string(host) + "\"");
    onHost = true;
    target.kind = Target::Kind::AllCars;  // a command there is for every car of this host
  } else if (anki && parts.size() == 3 && parts[1] == "Car" && parts[2] == "I") {
    target.kind = Target::Kind::AllCars;  // the controller's global commands
  } else if (anki && parts[1] == "Car" && parts.size() >= 4 && parts[3] == "I") {
    if (parts[2] == "all") {
      target.kind = Target::Kind::AllCars;
    } else {
      target.car = std::string(parts[2]);
      if (std::find(knownCars.begin(), knownCars.end(), target.car) == knownCars.end()) {
        std::string known;
        for (const auto& c : knownCars) known += (known.empty() ? "" : ", ") + c;
        return fail("unknown car \"" + quote(target.car) +
                    "\"; known cars: " + (known.empty() ? "none" : known) + " (or \"all\")");
      }
    }
  } else {
    return fail("not an intent topic; intents go to Anki/Host/" + std::string(host) +
                "/I (or below it), Anki/Car/I, Anki/Car/all/I or Anki/Car/<car>/I (or below it)");
  }

  auto j = parse(payload, limits);
  if (!j) return fail(j.error());
  if (!j->is_object())
    return fail("payload must be a JSON object, not " + typeName(*j) + " (" + excerpt(*j) + ")");

  Parsed action = onHost ? hostIntent(*j) : carCommand(*j);
  if (!action) return fail(action.error());
  if (std::holds_alternative<ConnectIntent>(*action) ||
      std::holds_alternative<CarsIntent>(*action) ||
      std::holds_alternative<CarStatusIntent>(*action))
    target.kind = Target::Kind::Host;
  return Intent{std::move(target), std::move(*action)};
}

Publication intentError(std::string_view host, const IntentError& error, Millis now) {
  // The topic and the sentence both come from the sender one way or another. They are cut until
  // the whole fits kMaxIntentError; the second cut fits whatever they hold (JSON escapes at most
  // sextuple a byte: \u001f). replace() turns any invalid UTF-8 left into U+FFFD, not a throw.
  std::string payload;
  for (auto [topicBytes, errorBytes] : {std::pair<std::size_t, std::size_t>{200, 800}, {32, 100}}) {
    Json j{{"timestamp", now},
           {"topic", quote(error.topic, topicBytes)},
           {"error", clip(error.message, errorBytes)}};
    payload = j.dump(-1, ' ', false, Json::error_handler_t::replace);
    if (payload.size() <= kMaxIntentError) break;
  }
  return {hostTopic(host, "S/IntentError"), std::move(payload), kStatusQos, false};
}
std::optional<std::string> controllerIntentPayload(const anki::Message& command) {
  Json j;
  std::visit(Overload{
                 [&](const anki::SetSpeed& m) {
                   if (m.respect_limit) return;  // no key for it in the controller's form
                   j = Json{{"speed", m.speed_mm_s}, {"acceleration", m.accel_mm_s2}};
                 },
                 [&](const anki::ChangeLane& m) {
                   if (m.hop_intent != 0 || m.tag != 0) return;
                   // "lane" names the command, "offset" is what the controller reads; the
                   // sideways speed is pitwall's (the controller uses its own)
                   j = Json{{"lane", mm(m.offset_mm)},
                            {"offset", mm(m.offset_mm)},
                            {"horizontalSpeed", m.h_speed_mm_s},
                            {"horizontalAcceleration", m.h_accel_mm_s2}};
                 },
                 [&](const anki::Turn& m) {
                   j = Json{{"turn", Json{{"type", static_cast<int>(m.type)},
                                          {"time", static_cast<int>(m.trigger)}}}};
                 },
                 [&](const anki::BatteryRequest&) {
                   j = Json{{"battery", true}};
                 },
                 [&](const anki::VersionRequest&) {
                   j = Json{{"version", true}};
                 },
                 [&](const anki::PingRequest&) {
                   j = Json{{"ping", true}};
                 },
                 [&](const auto&) {},
             },
             command);
  if (j.is_null()) return std::nullopt;
  return j.dump();
}

std::optional<std::string> intentPayload(const anki::Message& command) {
  if (!isCommand(command)) return std::nullopt;
  if (auto seed = controllerIntentPayload(command)) return seed;
  auto frame = anki::encode(command);
  return Json{{"type", "message"}, {"frame", toHex(frame.span(), "")}}.dump();
}
}  // namespace pitwall::topics
