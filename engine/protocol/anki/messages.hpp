#pragma once
// Every Anki Overdrive message as a value type (../shared/protocols/anki-overdrive.md, seed 000
// §4.3). Both directions share one variant: ids never overlap, so one codec serves the controller
// (vehicle model) and the vehicle side (simulator) alike.
#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <variant>

#include "engine/protocol/frame.hpp"

namespace pitwall::anki {

// A frame as sent over the air: [size][id][payload], at most 20 bytes.
using Frame = BoundedFrame<20>;

namespace id {
// controller → vehicle
inline constexpr std::uint8_t kDisconnect = 0x0d;
inline constexpr std::uint8_t kPingRequest = 0x16;
inline constexpr std::uint8_t kVersionRequest = 0x18;
inline constexpr std::uint8_t kBatteryRequest = 0x1a;
inline constexpr std::uint8_t kSetLights = 0x1d;
inline constexpr std::uint8_t kSetSpeed = 0x24;
inline constexpr std::uint8_t kChangeLane = 0x25;
inline constexpr std::uint8_t kCancelLaneChange = 0x26;
inline constexpr std::uint8_t kSetOffset = 0x2c;
inline constexpr std::uint8_t kTurn = 0x32;
inline constexpr std::uint8_t kLightsPattern = 0x33;
inline constexpr std::uint8_t kSetConfig = 0x45;
inline constexpr std::uint8_t kSdkMode = 0x90;
// vehicle → controller
inline constexpr std::uint8_t kPingResponse = 0x17;
inline constexpr std::uint8_t kVersionResponse = 0x19;
inline constexpr std::uint8_t kBatteryResponse = 0x1b;
inline constexpr std::uint8_t kPositionUpdate = 0x27;
inline constexpr std::uint8_t kTransitionUpdate = 0x29;
inline constexpr std::uint8_t kIntersectionUpdate = 0x2a;
inline constexpr std::uint8_t kDelocalized = 0x2b;
inline constexpr std::uint8_t kOffsetUpdate = 0x2d;
inline constexpr std::uint8_t kSpeedUpdate = 0x36;
inline constexpr std::uint8_t kCarStatus = 0x3f;
inline constexpr std::uint8_t kLaneChangeUpdate = 0x41;
inline constexpr std::uint8_t kAutoRecoveryEntered = 0x43;
inline constexpr std::uint8_t kAutoRecoverySucceeded = 0x44;
inline constexpr std::uint8_t kCollision = 0x4d;
inline constexpr std::uint8_t kCycleOvertime = 0x86;
}  // namespace id

// ---- controller → vehicle ----
struct Disconnect {
  bool operator==(const Disconnect&) const = default;
};
struct PingRequest {
  bool operator==(const PingRequest&) const = default;
};
struct VersionRequest {
  bool operator==(const VersionRequest&) const = default;
};
struct BatteryRequest {
  bool operator==(const BatteryRequest&) const = default;
};
struct SetLights {
  std::uint8_t mask = 0;  // low nibble: lights touched, high nibble: their values
  bool operator==(const SetLights&) const = default;
};
struct SetSpeed {
  std::int16_t speed_mm_s = 0;
  std::int16_t accel_mm_s2 = 0;
  bool respect_limit = false;
  bool operator==(const SetSpeed&) const = default;
};
struct ChangeLane {
  std::uint16_t h_speed_mm_s = 0;
  std::uint16_t h_accel_mm_s2 = 0;
  float offset_mm = 0;
  std::uint8_t hop_intent = 0;
  std::uint8_t tag = 0;
  bool operator==(const ChangeLane&) const = default;
};
struct CancelLaneChange {
  bool operator==(const CancelLaneChange&) const = default;
};
struct SetOffset {
  float offset_mm = 0;
  bool operator==(const SetOffset&) const = default;
};
enum class TurnType : std::uint8_t { None = 0, Left = 1, Right = 2, UTurn = 3, UTurnJump = 4 };
enum class TurnTrigger : std::uint8_t { Immediate = 0, Intersection = 1 };
struct Turn {
  TurnType type = TurnType::None;
  TurnTrigger trigger = TurnTrigger::Immediate;
  bool operator==(const Turn&) const = default;
};
struct LightChannel {
  std::uint8_t channel = 0;  // 0 red, 1 tail, 2 blue, 3 green, 4 front-left, 5 front-right
  std::uint8_t effect = 0;   // 0 steady, 1 fade, 2 throb, 3 flash, 4 random
  std::uint8_t start = 0;    // intensity 0..14
  std::uint8_t end = 0;
  std::uint8_t cycles_per_10s = 0;
  bool operator==(const LightChannel&) const = default;
};
struct LightsPattern {
  std::uint8_t channel_count = 0;  // ≤ 3
  std::array<LightChannel, 3> channels{};
  bool operator==(const LightsPattern&) const = default;
};
struct SetConfig {
  std::uint8_t super_code_parse_mask = 0;
  std::uint8_t track_material = 0;  // 0 plastic, 1 vinyl
  bool operator==(const SetConfig&) const = default;
};
struct SdkMode {
  bool on = true;
  std::uint8_t flags = 0x01;  // 0x01 override localization
  bool operator==(const SdkMode&) const = default;
};

// ---- vehicle → controller ----
struct PingResponse {
  bool operator==(const PingResponse&) const = default;
};
struct VersionResponse {
  std::uint16_t version = 0;
  bool operator==(const VersionResponse&) const = default;
};
struct BatteryResponse {
  std::uint16_t millivolts = 0;
  bool operator==(const BatteryResponse&) const = default;
};
struct PositionUpdate {
  std::uint8_t location_id = 0;
  std::uint8_t piece_id = 0;
  float offset_mm = 0;
  std::uint16_t speed_mm_s = 0;
  std::uint8_t parsing_flags = 0;  // low nibble bits read, 0x20 reverse driving, 0x40 reverse
                                   // parsing, 0x80 inverted colour
  std::uint8_t last_recv_lane_change_id = 0;
  std::uint8_t last_exec_lane_change_id = 0;
  std::uint16_t last_desired_lane_change_speed_mm_s = 0;
  std::uint16_t last_desired_speed_mm_s = 0;
  bool operator==(const PositionUpdate&) const = default;
};
struct TransitionUpdate {
  std::int8_t piece_idx = 0;
  std::int8_t prev_piece_idx = 0;
  float offset_mm = 0;
  std::optional<std::uint8_t> driving_direction;  // only firmware before 0x2b6e (size byte 18)
  std::uint8_t last_recv_lane_change_id = 0;
  std::uint8_t last_exec_lane_change_id = 0;
  std::uint16_t last_desired_lane_change_speed_mm_s = 0;
  std::int8_t average_follow_line_drift_px = 0;
  std::uint8_t had_lane_change_activity = 0;
  std::uint8_t uphill_counter = 0;
  std::uint8_t downhill_counter = 0;
  std::uint8_t left_wheel_distance_cm = 0;
  std::uint8_t right_wheel_distance_cm = 0;
  bool operator==(const TransitionUpdate&) const = default;
};
struct IntersectionUpdate {
  std::int8_t piece_idx = 0;
  float offset_mm = 0;
  std::uint8_t intersection_code = 0;  // 0 none, 1 entry first, 2 exit first, 3 entry second,
                                       // 4 exit second
  std::uint8_t is_exiting = 0;
  std::uint16_t mm_since_last_transition_bar = 0;
  std::optional<std::uint16_t> mm_since_last_intersection_code;  // absent in the older layout
  bool operator==(const IntersectionUpdate&) const = default;
};
struct Delocalized {
  bool operator==(const Delocalized&) const = default;
};
struct OffsetUpdate {
  float offset_mm = 0;
  std::uint8_t lane_change_id = 0;
  bool operator==(const OffsetUpdate&) const = default;
};
struct SpeedUpdate {
  std::int16_t desired_mm_s = 0;
  std::optional<std::int16_t> accel_mm_s2;  // not in firmware 0x266e's short form (size byte 3)
  std::optional<std::int16_t> actual_mm_s;  // not in firmware 0x266e's short form (size byte 3)
  bool operator==(const SpeedUpdate&) const = default;
};
struct CarStatus {
  bool on_track = false;
  bool on_charger = false;
  std::optional<bool> low_battery;    // newer firmware (size byte 5)
  std::optional<bool> fully_charged;  // newer firmware (size byte 5)
  bool operator==(const CarStatus&) const = default;
};
struct LaneChangeUpdate {
  float current_offset_mm = 0;
  float target_offset_mm = 0;
  std::uint16_t h_speed_mm_s = 0;
  std::int16_t v_speed_mm_s = 0;
  std::uint8_t lane_change_id = 0;
  bool operator==(const LaneChangeUpdate&) const = default;
};
struct AutoRecoveryEntered {
  bool operator==(const AutoRecoveryEntered&) const = default;
};
struct AutoRecoverySucceeded {
  bool operator==(const AutoRecoverySucceeded&) const = default;
};
struct Collision {
  std::uint8_t side = 0;
  std::uint8_t front_back = 0;
  bool operator==(const Collision&) const = default;
};
struct CycleOvertime {
  std::uint16_t count = 0;
  std::uint32_t average_us = 0;
  std::uint32_t max_us = 0;
  bool operator==(const CycleOvertime&) const = default;
};

// Any id not listed above: kept whole, never an error (protocol decision).
struct Unknown {
  std::uint8_t id = 0;
  Frame raw;
  bool operator==(const Unknown&) const = default;
};

using Message =
    std::variant<Disconnect, PingRequest, VersionRequest, BatteryRequest, SetLights, SetSpeed,
                 ChangeLane, CancelLaneChange, SetOffset, Turn, LightsPattern, SetConfig, SdkMode,
                 PingResponse, VersionResponse, BatteryResponse, PositionUpdate, TransitionUpdate,
                 IntersectionUpdate, Delocalized, OffsetUpdate, SpeedUpdate, CarStatus,
                 LaneChangeUpdate, AutoRecoveryEntered, AutoRecoverySucceeded, Collision,
                 CycleOvertime, Unknown>;

}  // namespace pitwall::anki
