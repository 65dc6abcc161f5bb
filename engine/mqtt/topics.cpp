// The seed's MQTT topic tree (seed 000 §4.4, ../shared/protocols/mqtt-topics.md), car → broker:
// identities, and the events and status a car's messages and its life make. Payloads keep the
// seed's key order (ordered_json), so golden strings are stable. The controller's whole-message
// events are in controller_events.cpp, intents in intents.cpp, the reading side in readers.cpp.
#include "engine/mqtt/topics.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "engine/core/hex.hpp"
#include "engine/core/overload.hpp"
#include "engine/mqtt/payload.hpp"
#include "engine/protocol/anki/advertisement.hpp"

namespace pitwall::topics {
using namespace detail;

namespace {

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

}  // namespace

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
                 [&](const anki::SpeedUpdate& m) {
                   if (m.actual_mm_s) st("Speed/Actual", *m.actual_mm_s);  // not in 0x266e's
                 },
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
  if (auto whole = messageEvent(car, message, now)) out.push_back(std::move(*whole));
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
  Json information{{"address", info.address},
                   {"identifier", info.identifier},
                   {"model", anki::modelName(info.model_id)},
                   {"modelId", info.model_id},
                   {"productId", info.product_id},
                   {"name", info.name}};
  if (info.pitwall) {  // what a remote reader knows the car's kind by (CarInfo)
    information["bridge"] = "pitwall";
    information["host"] = info.host;
  }
  return {status(carTopic(info.id, "S/Information"), information),
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

}  // namespace pitwall::topics
