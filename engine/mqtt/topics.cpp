// The seed's MQTT topic tree (seed 000 §4.4, ../shared/protocols/mqtt-topics.md) as pure
// functions. Payloads keep the seed's key order (ordered_json), so golden strings are stable.
#include "engine/mqtt/topics.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <tuple>
#include <type_traits>

#include <mosquitto.h>

#include "engine/core/hex.hpp"
#include "engine/core/overload.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "engine/protocol/anki/limits.hpp"

namespace pitwall::topics {
namespace {

// What pitwall writes keeps its keys in the order written (golden strings stay stable); what it
// reads is parsed into a map: ordered_json finds a key by a linear search, so a payload of
// thousands of distinct keys would cost quadratic time before any rate limit is applied.
using Json = nlohmann::ordered_json;
using In = nlohmann::json;

template <typename T, std::size_t I = 0>
constexpr std::size_t variantIndex() {
  if constexpr (std::is_same_v<std::variant_alternative_t<I, anki::Message>, T>)
    return I;
  else
    return variantIndex<T, I + 1>();
}

constexpr int kEventQos = 0;   // events: QoS 0, not retained (mqtt-topics.md)
constexpr int kStatusQos = 1;  // status: QoS 1, retained

std::string carTopic(std::string_view car, std::string_view rest) {
  return "Anki/Car/" + std::string(car) + "/" + std::string(rest);
}
std::string hostTopic(std::string_view host, std::string_view rest) {
  return "Anki/Host/" + std::string(host) + "/" + std::string(rest);
}

// Offsets are floats on the wire; 0.01 mm is far below what a car measures, and rounding keeps
// payloads free of float noise (-23.1f would print as -23.100000381469727).
double mm(double v) {
  return std::round(v * 100.0) / 100.0;
}

Publication event(std::string_view car, std::string_view name, const Json& value, Millis now) {
  Json j{{"timestamp", now}, {"value", value}};
  return {carTopic(car, "E/" + std::string(name)), j.dump(), kEventQos, false};
}

Publication status(std::string topic, const Json& payload) {
  return {std::move(topic), payload.dump(), kStatusQos, true};
}

Publication valueStatus(std::string_view car, std::string_view name, const Json& value,
                        Millis now) {
  return status(carTopic(car, "S/" + std::string(name)),
                Json{{"timestamp", now}, {"value", value}});
}

Publication onlineStatus(std::string_view car, bool online, bool charging, bool onTrack,
                         Millis now) {
  return status(
      carTopic(car, "S/CarStatus"),
      Json{{"timestamp", now}, {"online", online}, {"charging", charging}, {"onTrack", onTrack}});
}

std::string safe(std::string_view s, bool lower) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    auto u = static_cast<unsigned char>(c);
    if (lower) u = static_cast<unsigned char>(std::tolower(u));
    out += (std::isalnum(u) || c == '.' || c == '_' || c == '-') ? static_cast<char>(u) : '_';
  }
  return out;
}

bool isCommand(const anki::Message& m) {
  return m.index() <= variantIndex<anki::SdkMode>();
}

// At most `n` bytes of a sentence of ours, cut between two UTF-8 characters, then "…".
std::string clip(std::string_view s, std::size_t n) {
  if (s.size() <= n) return std::string(s);
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;
  return std::string(s.substr(0, n)) + "…";
}

// A value received, as an error message shows it: its JSON, cut and escaped (a string value of
// 60 KB stays a short sentence).
std::string excerpt(const In& v) {
  return quote(v.dump());
}

// Thrown by the parser callback at the depth limit: the parse stops there.
struct TooDeep {};

// nlohmann's message for a parse error quotes the token it read ("last read: '…'", "number
// overflow parsing '…'"): that token is the sender's text, of any length and any bytes (a string
// with invalid UTF-8 in it), so it is cut to its last 80 bytes and escaped like every quote.
std::string describe(const Json::exception& e) {
  std::string_view what = e.what();
  auto open = what.find('\'');
  auto close = what.rfind("'; expected ");
  if (close == std::string_view::npos || close <= open) close = what.rfind('\'');
  if (open == std::string_view::npos || close <= open) return quote(what, 400);
  std::string_view token = what.substr(open + 1, close - open - 1);
  std::string tail =
      token.size() > 80 ? "…" + quote(token.substr(token.size() - 80)) : quote(token);
  return quote(what.substr(0, open + 1), 400) + tail + quote(what.substr(close), 400);
}

// The one way a payload from the broker becomes JSON: size first, then a parse that stops at the
// depth limit; every exception of the parser becomes an error sentence.
Result<In, std::string> parse(std::string_view payload, const PayloadLimits& limits) {
  if (payload.size() > limits.maxBytes)
    return Unexpected{"payload is " + std::to_string(payload.size()) + " bytes, more than " +
                      std::to_string(limits.maxBytes) + " (it begins " + quote(payload) +
                      "); send a smaller payload, or raise the limit with --mqtt-max-payload"};
  In::parser_callback_t depth = [&](int level, In::parse_event_t event, In&) {
    // `level` counts the containers around this one
    if ((event == In::parse_event_t::object_start || event == In::parse_event_t::array_start) &&
        level >= limits.maxDepth)
      throw TooDeep{};
    return true;
  };
  try {
    return In::parse(payload, depth);
  } catch (const TooDeep&) {
    return Unexpected{"payload nests objects and arrays more than " +
                      std::to_string(limits.maxDepth) + " deep (it begins " + quote(payload) +
                      "); send flatter JSON"};
  } catch (const Json::out_of_range& e) {
    // 406: a number beyond a double (1e400) would otherwise be infinity
    return Unexpected{"payload holds a number beyond the range of a double: " + describe(e) +
                      "; send numbers within ±1.7e308 (and within the ranges of the intent)"};
  } catch (const Json::parse_error& e) {
    return Unexpected{"payload is not JSON: " + describe(e)};
  } catch (const Json::exception& e) {
    return Unexpected{"payload cannot be read: " + describe(e)};
  }
}

}  // namespace

std::string quote(std::string_view text, std::size_t maxBytes) {
  std::string out;
  std::size_t i = 0;
  for (; i < text.size() && i < maxBytes;) {
    auto b = static_cast<unsigned char>(text[i]);
    std::size_t n = b < 0x80             ? 1
                    : (b & 0xE0) == 0xC0 ? 2
                    : (b & 0xF0) == 0xE0 ? 3
                    : (b & 0xF8) == 0xF0 ? 4
                                         : 0;
    if (n == 1 && b >= 0x20 && b < 0x7f) {
      out += static_cast<char>(b);
      ++i;
      continue;
    }
    // libmosquitto's check of one character: well formed (no overlong form, no surrogate) and
    // printable (MQTT's rules refuse control characters and non-characters)
    if (n > 1 && i + n <= text.size() && i + n <= maxBytes &&
        mosquitto_validate_utf8(text.data() + i, static_cast<int>(n)) == MOSQ_ERR_SUCCESS) {
      out.append(text.substr(i, n));
      i += n;
      continue;
    }
    out += "\\x" + toHex(std::span<const std::uint8_t>(&b, 1), "");
    ++i;
  }
  if (i < text.size()) out += "…";
  return out;
}

std::string carId(std::string_view address) {
  std::string id;
  if (address.starts_with("ble:")) address.remove_prefix(4);
  // A bare BLE address: six hex pairs separated by ':'.
  bool ble = address.size() == 17;
  for (std::size_t i = 0; ble && i < address.size(); ++i) {
    ble = (i % 3 == 2) ? address[i] == ':' : std::isxdigit(static_cast<unsigned char>(address[i]));
  }
  if (ble) {
    for (char c : address) {
      if (c != ':') id += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
    return id;
  }
  std::string dashed(address);
  std::replace(dashed.begin(), dashed.end(), ':', '-');
  id = safe(dashed, true);
  if (id.empty() || id == "all") id = "_" + id;
  return id;
}

std::string hostId(std::string_view host) {
  std::string id = safe(host, false);
  return id.empty() ? "_" : id;
}

// ---- car → broker ----

namespace {

// ---- the seed's controller's whole-message events (ReturnMsgHandler.js) ----
//
// One table per message it publishes: the event's name (drive-sdk's protocol.h name) and its keys
// in the controller's order, each with the member it holds. fromMessage writes by it and
// readMessageEvent reads by it.

template <class T, class V>
struct Key {
  const char* name;
  V T::*member;
};
template <class T, class V>
Key(const char*, V T::*) -> Key<T, V>;

template <class T>
struct Controller;  // name and keys, for the messages the controller publishes

template <>
struct Controller<anki::PingResponse> {
  static constexpr const char* name = "ANKI_VEHICLE_MSG_V2C_PING_RESPONSE";
  static constexpr std::tuple<> keys{};
};
template <>
struct Controller<anki::VersionResponse> {
  static constexpr const char* name = "ANKI_VEHICLE_MSG_V2C_VERSION_RESPONSE";
  static constexpr std::tuple keys{Key{"value", &anki::VersionResponse::version}};
};
template <>
struct Controller<anki::BatteryResponse> {
  static constexpr const char* name = "ANKI_VEHICLE_MSG_V2C_BATTERY_LEVEL_RESPONSE";
  static constexpr std::tuple keys{Key{"value", &anki::BatteryResponse::millivolts}};
};
template <>
struct Controller<anki::PositionUpdate> {
  using M = anki::PositionUpdate;
  static constexpr const char* name = "ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE";
  static constexpr std::tuple keys{
      Key{"offset", &M::offset_mm},
      Key{"speed", &M::speed_mm_s},
      Key{"flag", &M::parsing_flags},
      Key{"pieceId", &M::piece_id},
      Key{"pieceLocation", &M::location_id},
      Key{"last_des_speed", &M::last_desired_speed_mm_s},
      Key{"last_rec_lane_change_cmd", &M::last_recv_lane_change_id},
      Key{"last_exe_lane_change_cmd", &M::last_exec_lane_change_id},
      Key{"last_des_lane_change_speed", &M::last_desired_lane_change_speed_mm_s}};
};
template <>
struct Controller<anki::TransitionUpdate> {
  using M = anki::TransitionUpdate;
  static constexpr const char* name = "ANKI_VEHICLE_MSG_V2C_LOCALIZATION_TRANSITION_UPDATE";
  static constexpr std::tuple keys{
      Key{"offset", &M::offset_mm},
      Key{"last_recv_lane_change_id", &M::last_recv_lane_change_id},
      Key{"last_exec_lane_change_id", &M::last_exec_lane_change_id},
      Key{"last_desired_lane_change_speed_mm_per_sec", &M::last_desired_lane_change_speed_mm_s},
      Key{"ave_follow_line_drift_pixels", &M::average_follow_line_drift_px},
      Key{"had_lane_change_activity", &M::had_lane_change_activity},
      Key{"uphill_counter", &M::uphill_counter},
      Key{"downhill_counter", &M::downhill_counter},
      Key{"left_wheel_dist_cm", &M::left_wheel_distance_cm},
      Key{"right_wheel_dist_cm", &M::right_wheel_distance_cm}};
};
template <>
struct Controller<anki::IntersectionUpdate> {
  using M = anki::IntersectionUpdate;
  static constexpr const char* name = "ANKI_VEHICLE_MSG_V2C_LOCALIZATION_INTERSECTION_UPDATE";
  static constexpr std::tuple keys{
      Key{"offset", &M::offset_mm}, Key{"intersection_code", &M::intersection_code},
      Key{"is_exiting", &M::is_exiting},
      Key{"mm_since_last_transition_bar", &M::mm_since_last_transition_bar},
      Key{"mm_since_last_intersection_code", &M::mm_since_last_intersection_code}};
};
template <>
struct Controller<anki::Delocalized> {
  static constexpr const char* name = "ANKI_VEHICLE_MSG_V2C_VEHICLE_DELOCALIZED";
  static constexpr std::tuple<> keys{};
};
template <>
struct Controller<anki::CarStatus> {  // "online": true first, written by hand
  static constexpr const char* name = "ANKI_VEHICLE_MSG_V2C_VEHICLE_STATUS";
  static constexpr std::tuple keys{Key{"charging", &anki::CarStatus::on_charger},
                                   Key{"onTrack", &anki::CarStatus::on_track}};
};

template <class T>
concept Published = requires {
  Controller<T>::name;
};

template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};

// The payload after "message_id" and "timestamp".
template <Published T>
Json controllerFields(const T& m) {
  Json j = Json::object();
  if constexpr (std::is_same_v<T, anki::CarStatus>) j["online"] = true;
  std::apply(
      [&](const auto&... key) {
        [[maybe_unused]] auto put = [&](const auto& k) {
          const auto& v = m.*(k.member);
          using V = std::decay_t<decltype(v)>;
          if constexpr (IsOptional<V>::value) {
            if (v) j[k.name] = *v;  // absent in the older layout
          } else if constexpr (std::is_same_v<V, bool>) {
            j[k.name] = v ? 1 : 0;  // 0/1, as the controller reads them (readUInt8)
          } else if constexpr (std::is_floating_point_v<V>) {
            j[k.name] = mm(v);
          } else {
            j[k.name] = v;
          }
        };
        (put(key), ...);
      },
      Controller<T>::keys);
  // the controller means reverse parsing (its own test of the bit never matches: it compares the
  // hex text with "0x40")
  if constexpr (std::is_same_v<T, anki::PositionUpdate>)
    j["isReverse"] = (m.parsing_flags & 0x40) != 0;
  return j;
}

}  // namespace

std::string_view messageEventName(const anki::Message& message) {
  return std::visit(
      []<class T>(const T&) -> std::string_view {
        if constexpr (Published<T>)
          return Controller<T>::name;
        else
          return "";
      },
      message);
}

std::vector<Publication> fromMessage(std::string_view car, const anki::Message& message,
                                     std::optional<double> pingRttSeconds, Millis now) {
  std::vector<Publication> out;
  auto ev = [&](std::string_view name, const Json& value) {
    out.push_back(event(car, name, value, now));
  };
  auto st = [&](std::string_view name, const Json& value) {
    out.push_back(valueStatus(car, name, value, now));
  };
  std::visit(Overload{
                 [&](const anki::PositionUpdate& m) {
                   ev("speed", m.speed_mm_s);
                   ev("last_desired_speed", m.last_desired_speed_mm_s);
                   ev("track_piece_id", m.piece_id);
                   ev("track_location_id", m.location_id);
                   ev("lane/offset/actual", mm(m.offset_mm));
                   ev("lane/desired_lane_change_speed", m.last_desired_lane_change_speed_mm_s);
                   st("Speed/Actual", m.speed_mm_s);
                   st("Lane/Actual", mm(m.offset_mm));
                 },
                 [&](const anki::TransitionUpdate& m) {
                   ev("lane/offset/actual", mm(m.offset_mm));
                   ev("lane/desired_lane_change_speed", m.last_desired_lane_change_speed_mm_s);
                   ev("ave_follow_line_drift_pixels", m.average_follow_line_drift_px);
                   ev("had_lane_change_activity", m.had_lane_change_activity);
                   ev("uphill_counter", m.uphill_counter);
                   ev("downhill_counter", m.downhill_counter);
                   ev("left_wheel_dist_cm", m.left_wheel_distance_cm);
                   ev("right_wheel_dist_cm", m.right_wheel_distance_cm);
                   st("Lane/Actual", mm(m.offset_mm));
                 },
                 [&](const anki::IntersectionUpdate& m) {
                   ev("lane/offset/actual", mm(m.offset_mm));
                   ev("intersection_code", m.intersection_code);
                   ev("mm_since_last_transition_bar", m.mm_since_last_transition_bar);
                   // absent in the older layout: nothing to report then
                   if (m.mm_since_last_intersection_code)
                     ev("mm_since_last_intersection_code", *m.mm_since_last_intersection_code);
                 },
                 [&](const anki::Delocalized&) {
                   // seed 000 §4.4.2.16: timestamp only
                   out.push_back({carTopic(car, "E/Delocalized"), Json{{"timestamp", now}}.dump(),
                                  kEventQos, false});
                 },
                 [&](const anki::OffsetUpdate& m) { st("Lane/Actual", mm(m.offset_mm)); },
                 [&](const anki::SpeedUpdate& m) { st("Speed/Actual", m.actual_mm_s); },
                 [&](const anki::PingResponse&) {
                   // round-trip time in ms (µs precision); null when no ping of ours was waiting.
                   // S/PingResp is where the seed's controller's clients read it; S/PingResponse
                   // is pitwall's earlier name, kept for the tools written against it.
                   Json rtt = nullptr;
                   if (pingRttSeconds) rtt = std::round(*pingRttSeconds * 1e6) / 1e3;
                   Json payload{{"timestamp", now}, {"rtt_ms", rtt}};
                   out.push_back(status(carTopic(car, "S/PingResp"), payload));
                   out.push_back(status(carTopic(car, "S/PingResponse"), payload));
                 },
                 [&](const anki::VersionResponse& m) { st("Version", m.version); },
                 [&](const anki::BatteryResponse& m) { st("BatteryLevel", m.millivolts); },
                 [&](const anki::CarStatus& m) {
                   out.push_back(onlineStatus(car, true, m.on_charger, m.on_track, now));
                 },
                 [&](const auto&) {},
             },
             message);
  std::visit(
      [&]<class T>(const T& m) {
        if constexpr (Published<T>) {
          Json j{{"message_id", anki::messageId(message)}, {"timestamp", now}};
          Json fields = controllerFields(m);  // items() refers to it: it must outlive the loop
          for (auto& [key, value] : fields.items()) j[key] = value;
          out.push_back({carTopic(car, "E/Messages/" + std::string(Controller<T>::name)), j.dump(),
                         kEventQos, false});
        }
      },
      message);
  return out;
}

Publication frameEvent(std::string_view car, std::span<const std::uint8_t> frame, Millis now) {
  return event(car, "frame", toHex(frame, ""), now);
}

std::vector<Publication> commandStatus(std::string_view car, const anki::Message& sent,
                                       Millis now) {
  std::vector<Publication> out;
  std::visit(Overload{
                 [&](const anki::SetSpeed& m) {
                   out.push_back(valueStatus(car, "Speed/Desired", m.speed_mm_s, now));
                 },
                 [&](const anki::ChangeLane& m) {
                   out.push_back(valueStatus(car, "Lane/Desired", mm(m.offset_mm), now));
                 },
                 [&](const anki::SetOffset& m) {
                   out.push_back(valueStatus(car, "Lane/Desired", mm(m.offset_mm), now));
                 },
                 [&](const auto&) {},
             },
             sent);
  return out;
}

std::vector<Publication> carJoined(const CarInfo& info, const CarState& state, Millis now) {
  // seed 000 §4.4.4.10 and §4.4.4.12
  return {status(carTopic(info.id, "S/Information"), Json{{"address", info.address},
                                                          {"identifier", info.identifier},
                                                          {"model", anki::modelName(info.model_id)},
                                                          {"modelId", info.model_id},
                                                          {"productId", info.product_id},
                                                          {"name", info.name}}),
          status(carTopic(info.id, "S/DiscoveryTime"), Json{{"timestamp", now}}),
          carOnline(info.id, state, now)};
}

Publication carOnline(std::string_view car, const CarState& state, Millis now) {
  return onlineStatus(car, true, state.on_charger, state.on_track, now);
}

Publication carLeft(std::string_view car, const CarState& state, Millis now) {
  return onlineStatus(car, false, state.on_charger, state.on_track, now);
}

Publication hostOnline(std::string_view host) {
  return status(hostTopic(host, "S/HostStatus"), Json{{"value", true}});
}

Publication hostWill(std::string_view host) {
  return status(hostTopic(host, "S/HostStatus"), Json{{"value", false}});
}

Publication hostCars(std::string_view host, std::span<const std::string> cars) {
  Json list = Json::array();
  for (const auto& c : cars) list.push_back(c);
  return status(hostTopic(host, "S/Cars"), list);
}

namespace {
Publication hostEvent(std::string_view host, std::string_view name, std::string_view car,
                      Millis now) {
  return {hostTopic(host, "E/" + std::string(name)),
          Json{{"timestamp", now}, {"Car", std::string(car)}}.dump(), kEventQos, false};
}
}  // namespace

Publication carConnected(std::string_view host, std::string_view car, Millis now) {
  return hostEvent(host, "CarConnected", car, now);
}

Publication carDisconnected(std::string_view host, std::string_view car, Millis now) {
  return hostEvent(host, "CarDisconnected", car, now);
}

Publication carDiscovered(std::string_view host, std::string_view car, Millis now) {
  // seed 000 §4.4.2.17: an event, so not retained
  return hostEvent(host, "CarDiscovered", car, now);
}

// ---- broker → intents ----

std::vector<std::string> intentSubscriptions(std::string_view host) {
  // As the seed's controller subscribes: "a/I/#" matches "a/I" itself too
  return {hostTopic(host, "I/#"), "Anki/Car/+/I/#", "Anki/Car/I"};
}

namespace {

using Parsed = Result<Action, std::string>;

std::string typeName(const In& v) {
  if (v.is_number_integer()) return "an integer";
  if (v.is_number()) return "a number";
  std::string name = v.type_name();
  return (name[0] == 'a' || name[0] == 'o' ? "an " : "a ") + name;
}

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
  std::string u = unit.empty() ? "" : " " + std::string(unit);
  if (d < lo || d > hi)
    return Unexpected{std::string(key) + " " + v.dump() + u + " is out of range " +
                      std::to_string(lo) + ".." + std::to_string(hi) + u};
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
  std::string u = unit.empty() ? "" : " " + std::string(unit);
  if (!(r >= lo && r <= hi))
    return Unexpected{std::string(key) + " " + excerpt(v) + u + " is out of range " +
                      std::to_string(lo) + ".." + std::to_string(hi) + u};
  return static_cast<int>(r);
}

Result<double, std::string> offsetValue(const In& v, std::string_view key) {
  namespace L = anki::limits;
  auto d = looseNumber(v, key);
  if (!d) return Unexpected{d.error()};
  if (!(*d >= L::kOffsetMin && *d <= L::kOffsetMax))
    return Unexpected{std::string(key) + " " + excerpt(v) + " mm is out of range " +
                      std::to_string(static_cast<int>(L::kOffsetMin)) + ".." +
                      std::to_string(static_cast<int>(L::kOffsetMax)) +
                      " mm (beyond it the car leaves the road)"};
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

std::vector<std::string_view> split(std::string_view s) {
  std::vector<std::string_view> parts;
  while (true) {
    auto slash = s.find('/');
    parts.push_back(s.substr(0, slash));
    if (slash == std::string_view::npos) return parts;
    s.remove_prefix(slash + 1);
  }
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

// ---- the reading side ----

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

std::optional<TopicParts> splitTopic(std::string_view topic) {
  auto parts = split(topic);
  if (parts.size() < 4 || parts[0] != "Anki" || parts[2].empty()) return std::nullopt;
  TopicParts out;
  if (parts[1] == "Car")
    out.kind = TopicParts::Kind::Car;
  else if (parts[1] == "Host")
    out.kind = TopicParts::Kind::Host;
  else
    return std::nullopt;
  out.id = std::string(parts[2]);
  out.rest = std::string(topic.substr(parts[0].size() + parts[1].size() + parts[2].size() + 3));
  return out;
}

namespace {

Result<In, std::string> object(std::string_view payload, const PayloadLimits& limits) {
  auto j = parse(payload, limits);
  if (!j) return j;
  if (!j->is_object()) return Unexpected{"payload must be a JSON object, not " + typeName(*j)};
  return j;
}

template <typename T>
Result<T, std::string> key(const In& j, const char* name) {
  auto it = j.find(name);
  if (it == j.end()) return Unexpected{std::string("missing key \"") + name + "\""};
  try {
    return it->get<T>();
  } catch (const Json::exception&) {
    return Unexpected{std::string("\"") + name + "\" has the wrong type (" + excerpt(*it) + ")"};
  }
}

// An unsigned integer no larger than `max` (nlohmann would wrap -1 into a uint32_t).
template <typename T>
Result<T, std::string> unsignedKey(const In& j, const char* name) {
  auto it = j.find(name);
  if (it == j.end()) return Unexpected{std::string("missing key \"") + name + "\""};
  constexpr auto max = std::numeric_limits<T>::max();
  if (!it->is_number_unsigned() || it->get<std::uint64_t>() > max)
    return Unexpected{std::string("\"") + name + "\" must be an integer 0.." + std::to_string(max) +
                      ", not " + excerpt(*it)};
  return static_cast<T>(it->get<std::uint64_t>());
}

}  // namespace

Result<CarInfo, std::string> readInformation(std::string_view car, std::string_view payload,
                                             const PayloadLimits& limits) {
  auto j = object(payload, limits);
  if (!j) return Unexpected{j.error()};
  CarInfo info;
  info.id = std::string(car);
  auto address = key<std::string>(*j, "address");
  if (!address) return Unexpected{address.error()};
  info.address = *address;
  // The seed's controller blanks every key when it disconnects the car: an empty address, the
  // rest not read.
  if (info.address.empty()) return info;
  auto identifier = unsignedKey<std::uint32_t>(*j, "identifier");
  if (!identifier) return Unexpected{identifier.error()};
  info.identifier = *identifier;
  auto model = unsignedKey<std::uint8_t>(*j, "modelId");
  if (!model) return Unexpected{model.error()};
  info.model_id = *model;
  // optional: the product id, and pitwall's name
  if (auto product = unsignedKey<std::uint16_t>(*j, "productId")) info.product_id = *product;
  if (auto name = key<std::string>(*j, "name")) info.name = *name;
  return info;
}

Result<CarOnline, std::string> readCarStatus(std::string_view payload,
                                             const PayloadLimits& limits) {
  auto j = object(payload, limits);
  if (!j) return Unexpected{j.error()};
  CarOnline out;
  auto online = key<bool>(*j, "online");
  if (!online) return Unexpected{online.error()};
  out.online = *online;
  if (auto c = key<bool>(*j, "charging")) out.charging = *c;
  if (auto t = key<bool>(*j, "onTrack")) out.onTrack = *t;
  return out;
}

Result<bool, std::string> readHostStatus(std::string_view payload, const PayloadLimits& limits) {
  auto j = object(payload, limits);
  if (!j) return Unexpected{j.error()};
  return key<bool>(*j, "value");
}

Result<std::vector<std::string>, std::string> readHostCars(std::string_view payload,
                                                           const PayloadLimits& limits) {
  auto j = parse(payload, limits);
  if (!j) return Unexpected{j.error()};
  const In* list = &*j;
  if (j->is_object()) {
    if (j->empty()) return std::vector<std::string>{};  // the seed's controller's "none"
    auto it = j->find("value");                         // earlier pitwall bridges
    if (it == j->end())
      return Unexpected{std::string("must be an array of car ids, not an object")};
    list = &*it;
  }
  if (!list->is_array())
    return Unexpected{"must be an array of car ids, not " + typeName(*list) + " (" +
                      excerpt(*list) + ")"};
  std::vector<std::string> out;
  for (const auto& id : *list) {
    if (!id.is_string())
      return Unexpected{"a car id must be a string, not " + typeName(id) + " (" + excerpt(id) +
                        ")"};
    out.push_back(id.get<std::string>());
  }
  return out;
}

Result<std::vector<std::uint8_t>, std::string> readFrameEvent(std::string_view payload,
                                                              const PayloadLimits& limits) {
  auto j = object(payload, limits);
  if (!j) return Unexpected{j.error()};
  auto text = key<std::string>(*j, "value");
  if (!text) return Unexpected{text.error()};
  auto bytes = fromHex(*text);
  if (!bytes) return Unexpected{quote(bytes.error())};  // a pair may cut a character in two
  return bytes;
}

namespace {

// A field of an E/Messages payload: absent is 0 (the controller always sends every key it has);
// present, it must be a number within the field's type.
template <typename T>
Result<T, std::string> wireField(const In& j, const char* name) {
  auto it = j.find(name);
  if (it == j.end()) return T{};
  if (it->is_boolean()) return static_cast<T>(it->get<bool>());
  if (!it->is_number())
    return Unexpected{std::string("\"") + name + "\" must be a number, not " + typeName(*it) +
                      " (" + excerpt(*it) + ")"};
  double d = it->get<double>();
  if constexpr (std::is_floating_point_v<T>) {
    if (!(std::abs(d) <= std::numeric_limits<T>::max()))
      return Unexpected{std::string("\"") + name + "\" " + excerpt(*it) + " is beyond a float"};
    return static_cast<T>(d);
  } else {
    constexpr double lo = std::numeric_limits<T>::min(), hi = std::numeric_limits<T>::max();
    if (!(d >= lo && d <= hi) || d != std::floor(d))
      return Unexpected{std::string("\"") + name + "\" must be an integer " +
                        std::to_string(static_cast<long long>(lo)) + ".." +
                        std::to_string(static_cast<long long>(hi)) + ", not " + excerpt(*it)};
    return static_cast<T>(d);
  }
}

}  // namespace

Result<std::optional<anki::Message>, std::string> readMessageEvent(std::string_view name,
                                                                   std::string_view payload,
                                                                   const PayloadLimits& limits) {
  using Out = Result<std::optional<anki::Message>, std::string>;
  // Which message the name is: one of the published ones (Controller<T>).
  std::optional<anki::Message> kind;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    auto match = [&]<class T>(std::type_identity<T>) {
      if constexpr (Published<T>)
        if (!kind && name == Controller<T>::name) kind = T{};
    };
    (match(std::type_identity<std::variant_alternative_t<I, anki::Message>>{}), ...);
  }
  (std::make_index_sequence<std::variant_size_v<anki::Message>>{});
  if (!kind) return std::optional<anki::Message>{};
  auto j = object(payload, limits);
  if (!j) return Unexpected{j.error()};
  std::string error;
  std::visit(
      [&]<class T>(T& m) {
        if constexpr (Published<T>) {
          std::apply(
              [&](const auto&... key) {
                [[maybe_unused]] auto get = [&](const auto& k) {
                  auto& member = m.*(k.member);
                  using V = std::decay_t<decltype(member)>;
                  if (!error.empty()) return;
                  if constexpr (IsOptional<V>::value) {
                    if (!j->contains(k.name)) return;  // the older layout
                    auto v = wireField<typename V::value_type>(*j, k.name);
                    if (v)
                      member = *v;
                    else
                      error = v.error();
                  } else {
                    auto v = wireField<V>(*j, k.name);
                    if (v)
                      member = *v;
                    else
                      error = v.error();
                  }
                };
                (get(key), ...);
              },
              Controller<T>::keys);
        }
      },
      *kind);
  if (!error.empty()) return Unexpected{error};
  return Out{std::move(kind)};
}

}  // namespace pitwall::topics
