#pragma once
// What each message is made of, written once: its id, its kebab-case name, the size bytes it may
// have, and its fields in wire order, each with the name it goes by in JSON (= the struct member's
// name, which carries the unit). The codec reads and writes by walking the field list; the JSON
// formatter prints by walking it too. Adding a message or a field means writing it here (and in
// messages.hpp), nowhere else.
//
// Private to engine/protocol/anki: codec.cpp and message_json.cpp.
// Sources: anki-overdrive.md "Frame", "Controller → vehicle", "Vehicle → controller"; seed 000
// §4.3.2, §4.3.4, §4.3.5.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <tuple>
#include <type_traits>

#include "engine/protocol/anki/messages.hpp"

namespace pitwall::anki::fields {

// The size bytes (= frame length − 1) a message may have. Most have one. A few have a shorter
// and a longer form told apart by the size byte alone: optional fields are in the longer one; a
// documented form may end in bytes no field carries (set speed's size 7, the version response's
// 4-byte form), accepted and not kept. A frame longer than the longer form is read by it and the
// bytes past it are the codec's extraBytes(), kept by whoever receives the frame
// (anki-overdrive.md **Decision**). A frame shorter than the shorter form is refused, except the
// short command forms cars obey, which decodeCommand() takes (codec.cpp, kShortForms).
struct Sizes {
  std::uint8_t shorter;
  std::uint8_t longer;
};

struct Layout {
  std::uint8_t id;
  std::string_view name;  // kebab-case, stable: scripts and recordings use it
  Sizes sizes;
  std::uint8_t zeros_after = 0;  // bytes written as zero after the last field
};

// One field: its JSON name and the member that holds it.
template <class T, class V>
struct Field {
  std::string_view name;
  V T::*member;
};
template <class T, class V>
Field(std::string_view, V T::*) -> Field<T, V>;  // for compilers without aggregate deduction

template <class T>
struct Spec;  // Spec<M>::layout and Spec<M>::fields (a tuple of Field, wire order) per message

struct NoFields {
  static constexpr std::tuple<> fields{};
};

// A struct with a field list: every message, and the lights pattern's channel slots.
template <class T>
concept Described = requires {
  Spec<T>::fields;
};

// f(field) for each field of T, in wire order.
template <Described T, class F>
constexpr void forEach(F&& f) {
  std::apply([&](const auto&... field) { (f(field), ...); }, Spec<T>::fields);
}

template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};

// ---- controller → vehicle (anki-overdrive.md "Controller → vehicle"; seed 000 §4.3.4) ----

template <>
struct Spec<Disconnect> : NoFields {
  static constexpr Layout layout{id::kDisconnect, "disconnect", {1, 1}};
};
template <>
struct Spec<PingRequest> : NoFields {  // seed 000 §4.3.4.2: 01 16
  static constexpr Layout layout{id::kPingRequest, "ping-request", {1, 1}};
};
template <>
struct Spec<VersionRequest> : NoFields {  // seed 000 §4.3.4.8: 01 18
  static constexpr Layout layout{id::kVersionRequest, "version-request", {1, 1}};
};
template <>
struct Spec<BatteryRequest> : NoFields {  // seed 000 §4.3.4.7: 01 1a
  static constexpr Layout layout{id::kBatteryRequest, "battery-request", {1, 1}};
};
template <>
struct Spec<SetLights> {
  using M = SetLights;
  static constexpr Layout layout{id::kSetLights, "set-lights", {2, 2}};
  static constexpr std::tuple fields{Field{"mask", &M::mask}};
};
// seed 000 §4.3.4.3: i16 speed, i16 accel; anki-overdrive.md: + u8 respect limit (size 6, as in
// drive-sdk's golden vector 06 24 e8 03 a8 61 00); newer firmware takes a trailing byte (size 7)
// that we accept and do not model. Cars also obey it without the respect-limit byte (size 5,
// py-drivesdk): decodeCommand() reads that form, decode() does not.
template <>
struct Spec<SetSpeed> {
  using M = SetSpeed;
  static constexpr Layout layout{id::kSetSpeed, "set-speed", {6, 7}};
  static constexpr std::tuple fields{
      Field{"speed_mm_s", &M::speed_mm_s},
      Field{"accel_mm_s2", &M::accel_mm_s2},
      Field{"respect_limit", &M::respect_limit},
  };
};
// seed 000 §4.3.4.4; anki-overdrive.md: + u8 hop intent, u8 tag (size 11).
template <>
struct Spec<ChangeLane> {
  using M = ChangeLane;
  static constexpr Layout layout{id::kChangeLane, "change-lane", {11, 11}};
  static constexpr std::tuple fields{
      Field{"h_speed_mm_s", &M::h_speed_mm_s},
      Field{"h_accel_mm_s2", &M::h_accel_mm_s2},
      Field{"offset_mm", &M::offset_mm},
      Field{"hop_intent", &M::hop_intent},
      Field{"tag", &M::tag},
  };
};
template <>
struct Spec<CancelLaneChange> : NoFields {
  static constexpr Layout layout{id::kCancelLaneChange, "cancel-lane-change", {1, 1}};
};
// seed 000 §4.3.4.5 writes size 3 in its example, but an f32 payload makes size 5
// (anki-overdrive.md).
template <>
struct Spec<SetOffset> {
  using M = SetOffset;
  static constexpr Layout layout{id::kSetOffset, "set-offset", {5, 5}};
  static constexpr std::tuple fields{Field{"offset_mm", &M::offset_mm}};
};
template <>
struct Spec<Turn> {  // seed 000 §4.3.4.6
  using M = Turn;
  static constexpr Layout layout{id::kTurn, "turn", {3, 3}};
  static constexpr std::tuple fields{Field{"type", &M::type}, Field{"trigger", &M::trigger}};
};
// anki-overdrive.md: u8 channel count, then always 3 channel slots (size 17).
template <>
struct Spec<LightsPattern> {
  using M = LightsPattern;
  static constexpr Layout layout{id::kLightsPattern, "lights-pattern", {17, 17}};
  static constexpr std::tuple fields{
      Field{"channel_count", &M::channel_count},
      Field{"channels", &M::channels},
  };
};
// One channel slot of a lights pattern: 5 bytes, no layout of its own.
template <>
struct Spec<LightChannel> {
  using M = LightChannel;
  static constexpr std::tuple fields{
      Field{"channel", &M::channel},
      Field{"effect", &M::effect},
      Field{"start", &M::start},
      Field{"end", &M::end},
      Field{"cycles_per_10s", &M::cycles_per_10s},
  };
};
template <>
struct Spec<SetConfig> {
  using M = SetConfig;
  static constexpr Layout layout{id::kSetConfig, "set-config", {3, 3}};
  static constexpr std::tuple fields{
      Field{"super_code_parse_mask", &M::super_code_parse_mask},
      Field{"track_material", &M::track_material},
  };
};
template <>
struct Spec<SdkMode> {  // seed 000 §4.3.4.1
  using M = SdkMode;
  static constexpr Layout layout{id::kSdkMode, "sdk-mode", {3, 3}};
  static constexpr std::tuple fields{Field{"on", &M::on}, Field{"flags", &M::flags}};
};

// ---- vehicle → controller (anki-overdrive.md "Vehicle → controller"; seed 000 §4.3.5) ----

template <>
struct Spec<PingResponse> : NoFields {
  static constexpr Layout layout{id::kPingResponse, "ping-response", {1, 1}};
};
// anki-overdrive.md: some firmware sends 4 payload bytes; only the first u16 is the version.
template <>
struct Spec<VersionResponse> {
  using M = VersionResponse;
  static constexpr Layout layout{id::kVersionResponse, "version-response", {3, 5}};
  static constexpr std::tuple fields{Field{"version", &M::version}};
};
template <>
struct Spec<BatteryResponse> {
  using M = BatteryResponse;
  static constexpr Layout layout{id::kBatteryResponse, "battery-response", {3, 3}};
  static constexpr std::tuple fields{Field{"millivolts", &M::millivolts}};
};
// seed 000 §4.3.5.3 (drive-sdk's packed struct).
template <>
struct Spec<PositionUpdate> {
  using M = PositionUpdate;
  static constexpr Layout layout{id::kPositionUpdate, "position-update", {16, 16}};
  static constexpr std::tuple fields{
      Field{"location_id", &M::location_id},
      Field{"piece_id", &M::piece_id},
      Field{"offset_mm", &M::offset_mm},
      Field{"speed_mm_s", &M::speed_mm_s},
      Field{"parsing_flags", &M::parsing_flags},
      Field{"last_recv_lane_change_id", &M::last_recv_lane_change_id},
      Field{"last_exec_lane_change_id", &M::last_exec_lane_change_id},
      Field{"last_desired_lane_change_speed_mm_s", &M::last_desired_lane_change_speed_mm_s},
      Field{"last_desired_speed_mm_s", &M::last_desired_speed_mm_s},
  };
};
// seed 000 §4.3.5.4 (size 17). anki-overdrive.md "Firmware variants": before firmware 0x2b6e a
// u8 driving direction follows the offset (size 18) and every later field moves by one byte.
template <>
struct Spec<TransitionUpdate> {
  using M = TransitionUpdate;
  static constexpr Layout layout{id::kTransitionUpdate, "transition-update", {17, 18}};
  static constexpr std::tuple fields{
      Field{"piece_idx", &M::piece_idx},
      Field{"prev_piece_idx", &M::prev_piece_idx},
      Field{"offset_mm", &M::offset_mm},
      Field{"driving_direction", &M::driving_direction},
      Field{"last_recv_lane_change_id", &M::last_recv_lane_change_id},
      Field{"last_exec_lane_change_id", &M::last_exec_lane_change_id},
      Field{"last_desired_lane_change_speed_mm_s", &M::last_desired_lane_change_speed_mm_s},
      Field{"average_follow_line_drift_px", &M::average_follow_line_drift_px},
      Field{"had_lane_change_activity", &M::had_lane_change_activity},
      Field{"uphill_counter", &M::uphill_counter},
      Field{"downhill_counter", &M::downhill_counter},
      Field{"left_wheel_distance_cm", &M::left_wheel_distance_cm},
      Field{"right_wheel_distance_cm", &M::right_wheel_distance_cm},
  };
};
// seed 000 §4.3.5.5's struct ends after mm_since_last_transition_bar (the older size 10);
// anki-overdrive.md: newer firmware adds u16 mm since last intersection code (size 12).
template <>
struct Spec<IntersectionUpdate> {
  using M = IntersectionUpdate;
  static constexpr Layout layout{id::kIntersectionUpdate, "intersection-update", {10, 12}};
  static constexpr std::tuple fields{
      Field{"piece_idx", &M::piece_idx},
      Field{"offset_mm", &M::offset_mm},
      Field{"intersection_code", &M::intersection_code},
      Field{"is_exiting", &M::is_exiting},
      Field{"mm_since_last_transition_bar", &M::mm_since_last_transition_bar},
      Field{"mm_since_last_intersection_code", &M::mm_since_last_intersection_code},
  };
};
template <>
struct Spec<Delocalized> : NoFields {  // seed 000 §4.3.5.6
  static constexpr Layout layout{id::kDelocalized, "delocalized", {1, 1}};
};
template <>
struct Spec<OffsetUpdate> {
  using M = OffsetUpdate;
  static constexpr Layout layout{id::kOffsetUpdate, "offset-update", {6, 6}};
  static constexpr std::tuple fields{
      Field{"offset_mm", &M::offset_mm},
      Field{"lane_change_id", &M::lane_change_id},
  };
};
// Newer firmware: desired, acceleration, actual (size 7). Firmware 0x266e sends two payload bytes
// (IBM's example `03 36 00 00`, ../shared/realdata): read as the desired speed, the first field
// of the newer layout (an assumption, docs/simulator.md "Firmware families").
template <>
struct Spec<SpeedUpdate> {
  using M = SpeedUpdate;
  static constexpr Layout layout{id::kSpeedUpdate, "speed-update", {3, 7}};
  static constexpr std::tuple fields{
      Field{"desired_mm_s", &M::desired_mm_s},
      Field{"accel_mm_s2", &M::accel_mm_s2},
      Field{"actual_mm_s", &M::actual_mm_s},
  };
};
// seed 000 §4.3.5.7: on track, on charger (size 3); anki-overdrive.md: newer firmware adds low
// battery and fully charged (size 5).
template <>
struct Spec<CarStatus> {
  using M = CarStatus;
  static constexpr Layout layout{id::kCarStatus, "car-status", {3, 5}};
  static constexpr std::tuple fields{
      Field{"on_track", &M::on_track},
      Field{"on_charger", &M::on_charger},
      Field{"low_battery", &M::low_battery},
      Field{"fully_charged", &M::fully_charged},
  };
};
// anki-overdrive.md gives size byte 15, but its fields end at @14 (a 15-byte frame, size 14).
// Decision: read both; write size 15 with the unexplained last byte @15 as zero.
template <>
struct Spec<LaneChangeUpdate> {
  using M = LaneChangeUpdate;
  static constexpr Layout layout{.id = id::kLaneChangeUpdate,
                                 .name = "lane-change-update",
                                 .sizes = {14, 15},
                                 .zeros_after = 1};
  static constexpr std::tuple fields{
      Field{"current_offset_mm", &M::current_offset_mm},
      Field{"target_offset_mm", &M::target_offset_mm},
      Field{"h_speed_mm_s", &M::h_speed_mm_s},
      Field{"v_speed_mm_s", &M::v_speed_mm_s},
      Field{"lane_change_id", &M::lane_change_id},
  };
};
template <>
struct Spec<AutoRecoveryEntered> : NoFields {
  static constexpr Layout layout{id::kAutoRecoveryEntered, "auto-recovery-entered", {1, 1}};
};
template <>
struct Spec<AutoRecoverySucceeded> : NoFields {
  static constexpr Layout layout{id::kAutoRecoverySucceeded, "auto-recovery-succeeded", {1, 1}};
};
template <>
struct Spec<Collision> {
  using M = Collision;
  static constexpr Layout layout{id::kCollision, "collision", {3, 3}};
  static constexpr std::tuple fields{Field{"side", &M::side}, Field{"front_back", &M::front_back}};
};
template <>
struct Spec<CycleOvertime> {
  using M = CycleOvertime;
  static constexpr Layout layout{id::kCycleOvertime, "cycle-overtime", {11, 11}};
  static constexpr std::tuple fields{
      Field{"count", &M::count},
      Field{"average_us", &M::average_us},
      Field{"max_us", &M::max_us},
  };
};

}  // namespace pitwall::anki::fields
