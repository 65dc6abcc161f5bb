// The seed's controller's whole-message events, E/Messages/ANKI_VEHICLE_MSG_V2C_<NAME>
// (hofdo/nodejsankisdk ReturnMsgHandler.js): written for a car's message (messageEvent), and read
// back into the message they were made from (readMessageEvent) for a remote car whose bridge
// sends no E/frame.
#include <cmath>
#include <limits>
#include <tuple>
#include <type_traits>
#include <utility>

#include "engine/mqtt/payload.hpp"
#include "engine/mqtt/topics.hpp"
#include "engine/protocol/anki/codec.hpp"

namespace pitwall::topics {
using namespace detail;

namespace {

// ---- the seed's controller's whole-message events (ReturnMsgHandler.js) ----
//
// One table per message it publishes: the event's name (drive-sdk's protocol.h name) and its keys
// in the controller's order, each with the member it holds. messageEvent writes by it and
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
std::optional<Publication> messageEvent(std::string_view car, const anki::Message& message,
                                        Millis now) {
  std::optional<Publication> out;
  std::visit(
      [&]<class T>(const T& m) {
        if constexpr (Published<T>) {
          Json j{{"message_id", anki::messageId(message)}, {"timestamp", now}};
          Json fields = controllerFields(m);  // items() refers to it: it must outlive the loop
          for (auto& [key, value] : fields.items()) j[key] = value;
          out = Publication{carTopic(car, "E/Messages/" + std::string(Controller<T>::name)),
                            j.dump(), kEventQos, false};
        }
      },
      message);
  return out;
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
