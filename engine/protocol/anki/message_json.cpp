// Messages as JSON objects for `pitwall decode` and `--record` files. Field names are the struct
// field names (they carry the unit); optional fields are left out when absent.
#include "engine/protocol/anki/message_json.hpp"

#include <charconv>
#include <cmath>
#include <string>
#include <type_traits>

namespace pitwall::anki {
namespace {

using nlohmann::json;

std::string hexByte(std::uint8_t b) {
  static constexpr char kDigits[] = "0123456789abcdef";
  return {kDigits[b >> 4], kDigits[b & 0x0f]};
}

// A float as the shortest decimal that reads back to it (20.0f → 20, 0.1f → 0.1, not
// 0.10000000149011612). JSON has no NaN or infinity: those become null (nlohmann's choice).
json number(float v) {
  if (!std::isfinite(v)) return nullptr;
  char buf[32];
  const auto end = std::to_chars(buf, buf + sizeof buf, v).ptr;
  double d = v;
  std::from_chars(buf, end, d);
  return d;
}

// Enum fields as words; a value outside the enum (a decoded frame may hold one) stays a number.
json word(TurnType t) {
  switch (t) {
    case TurnType::None:
      return "none";
    case TurnType::Left:
      return "left";
    case TurnType::Right:
      return "right";
    case TurnType::UTurn:
      return "uturn";
    case TurnType::UTurnJump:
      return "uturn-jump";
  }
  return static_cast<int>(t);
}

json word(TurnTrigger t) {
  switch (t) {
    case TurnTrigger::Immediate:
      return "immediate";
    case TurnTrigger::Intersection:
      return "intersection";
  }
  return static_cast<int>(t);
}

void fields(json&, const Disconnect&) {}
void fields(json&, const PingRequest&) {}
void fields(json&, const VersionRequest&) {}
void fields(json&, const BatteryRequest&) {}
void fields(json&, const CancelLaneChange&) {}
void fields(json&, const PingResponse&) {}
void fields(json&, const Delocalized&) {}
void fields(json&, const AutoRecoveryEntered&) {}
void fields(json&, const AutoRecoverySucceeded&) {}

void fields(json& j, const SetLights& m) {
  j["mask"] = m.mask;
}

void fields(json& j, const SetSpeed& m) {
  j["speed_mm_s"] = m.speed_mm_s;
  j["accel_mm_s2"] = m.accel_mm_s2;
  j["respect_limit"] = m.respect_limit;
}

void fields(json& j, const ChangeLane& m) {
  j["h_speed_mm_s"] = m.h_speed_mm_s;
  j["h_accel_mm_s2"] = m.h_accel_mm_s2;
  j["offset_mm"] = number(m.offset_mm);
  j["hop_intent"] = m.hop_intent;
  j["tag"] = m.tag;
}

void fields(json& j, const SetOffset& m) {
  j["offset_mm"] = number(m.offset_mm);
}

void fields(json& j, const Turn& m) {
  j["type"] = word(m.type);
  j["trigger"] = word(m.trigger);
}

// Only the channels in use (channel_count, at most the 3 slots the frame has).
void fields(json& j, const LightsPattern& m) {
  j["channel_count"] = m.channel_count;
  json channels = json::array();
  for (std::size_t i = 0; i < m.channel_count && i < m.channels.size(); ++i) {
    const auto& c = m.channels[i];
    channels.push_back({{"channel", c.channel},
                        {"effect", c.effect},
                        {"start", c.start},
                        {"end", c.end},
                        {"cycles_per_10s", c.cycles_per_10s}});
  }
  j["channels"] = std::move(channels);
}

void fields(json& j, const SetConfig& m) {
  j["super_code_parse_mask"] = m.super_code_parse_mask;
  j["track_material"] = m.track_material;
}

void fields(json& j, const SdkMode& m) {
  j["on"] = m.on;
  j["flags"] = m.flags;
}

void fields(json& j, const VersionResponse& m) {
  j["version"] = m.version;
}
void fields(json& j, const BatteryResponse& m) {
  j["millivolts"] = m.millivolts;
}

void fields(json& j, const PositionUpdate& m) {
  j["location_id"] = m.location_id;
  j["piece_id"] = m.piece_id;
  j["offset_mm"] = number(m.offset_mm);
  j["speed_mm_s"] = m.speed_mm_s;
  j["parsing_flags"] = m.parsing_flags;
  j["last_recv_lane_change_id"] = m.last_recv_lane_change_id;
  j["last_exec_lane_change_id"] = m.last_exec_lane_change_id;
  j["last_desired_lane_change_speed_mm_s"] = m.last_desired_lane_change_speed_mm_s;
  j["last_desired_speed_mm_s"] = m.last_desired_speed_mm_s;
}

void fields(json& j, const TransitionUpdate& m) {
  j["piece_idx"] = m.piece_idx;
  j["prev_piece_idx"] = m.prev_piece_idx;
  j["offset_mm"] = number(m.offset_mm);
  if (m.driving_direction) j["driving_direction"] = *m.driving_direction;
  j["last_recv_lane_change_id"] = m.last_recv_lane_change_id;
  j["last_exec_lane_change_id"] = m.last_exec_lane_change_id;
  j["last_desired_lane_change_speed_mm_s"] = m.last_desired_lane_change_speed_mm_s;
  j["average_follow_line_drift_px"] = m.average_follow_line_drift_px;
  j["had_lane_change_activity"] = m.had_lane_change_activity;
  j["uphill_counter"] = m.uphill_counter;
  j["downhill_counter"] = m.downhill_counter;
  j["left_wheel_distance_cm"] = m.left_wheel_distance_cm;
  j["right_wheel_distance_cm"] = m.right_wheel_distance_cm;
}

void fields(json& j, const IntersectionUpdate& m) {
  j["piece_idx"] = m.piece_idx;
  j["offset_mm"] = number(m.offset_mm);
  j["intersection_code"] = m.intersection_code;
  j["is_exiting"] = m.is_exiting;
  j["mm_since_last_transition_bar"] = m.mm_since_last_transition_bar;
  if (m.mm_since_last_intersection_code) {
    j["mm_since_last_intersection_code"] = *m.mm_since_last_intersection_code;
  }
}

void fields(json& j, const OffsetUpdate& m) {
  j["offset_mm"] = number(m.offset_mm);
  j["lane_change_id"] = m.lane_change_id;
}

void fields(json& j, const SpeedUpdate& m) {
  j["desired_mm_s"] = m.desired_mm_s;
  j["accel_mm_s2"] = m.accel_mm_s2;
  j["actual_mm_s"] = m.actual_mm_s;
}

void fields(json& j, const CarStatus& m) {
  j["on_track"] = m.on_track;
  j["on_charger"] = m.on_charger;
  if (m.low_battery) j["low_battery"] = *m.low_battery;
  if (m.fully_charged) j["fully_charged"] = *m.fully_charged;
}

void fields(json& j, const LaneChangeUpdate& m) {
  j["current_offset_mm"] = number(m.current_offset_mm);
  j["target_offset_mm"] = number(m.target_offset_mm);
  j["h_speed_mm_s"] = m.h_speed_mm_s;
  j["v_speed_mm_s"] = m.v_speed_mm_s;
  j["lane_change_id"] = m.lane_change_id;
}

void fields(json& j, const Collision& m) {
  j["side"] = m.side;
  j["front_back"] = m.front_back;
}

void fields(json& j, const CycleOvertime& m) {
  j["count"] = m.count;
  j["average_us"] = m.average_us;
  j["max_us"] = m.max_us;
}

// The whole frame as space-separated hex bytes: "03 99 01 02".
void fields(json& j, const Unknown& m) {
  std::string raw;
  for (const auto b : m.raw.span()) {
    if (!raw.empty()) raw += ' ';
    raw += hexByte(b);
  }
  j["raw"] = std::move(raw);
}

}  // namespace

json toJson(const Message& message) {
  json j = json::object();
  j["name"] = name(message);
  j["id"] = "0x" + hexByte(messageId(message));
  std::visit([&](const auto& m) { fields(j, m); }, message);
  return j;
}

}  // namespace pitwall::anki
