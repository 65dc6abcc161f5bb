// bytes ⇄ messages for the Anki Overdrive protocol (anki-overdrive.md "Frame", "Controller →
// vehicle", "Vehicle → controller"; seed 000 §4.3.2, §4.3.4, §4.3.5).
//
// One `Spec<T>` per message says everything about it: id, name, the size bytes it may have, and
// its fields in wire order. Reading and writing both walk that one field list, so the two
// directions cannot drift apart. decode() finds the spec by id in a 256-entry table built at
// compile time: the hot path (a position update) is a lookup, a length check and a few loads into
// the result itself — no allocation, no exceptions, no strings.
#include "engine/protocol/anki/codec.hpp"

#include <array>
#include <bit>
#include <cassert>
#include <cstring>
#include <type_traits>
#include <utility>

namespace pitwall::anki {
namespace {

// Fields of an optional tail or middle (older/newer firmware) are on the wire in the long form
// only; see Sizes.
template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};

// Reads little-endian fields from a frame whose length was checked against its layout first.
class Reader {
 public:
  Reader(std::span<const std::uint8_t> frame, bool long_form)
      : frame_(frame), long_form_(long_form) {}

  void get(std::uint8_t& v) {
    assert(at_ < frame_.size());
    v = frame_[at_++];
  }
  void get(bool& v) { v = next() != 0; }
  void get(std::int8_t& v) { v = static_cast<std::int8_t>(next()); }
  void get(std::uint16_t& v) {
    const unsigned lo = next();  // its own statement: the two reads must happen in order
    v = static_cast<std::uint16_t>(lo | (next() << 8));
  }
  void get(std::int16_t& v) {
    std::uint16_t u = 0;
    get(u);
    v = static_cast<std::int16_t>(u);
  }
  void get(std::uint32_t& v) {
    std::uint16_t lo = 0, hi = 0;
    get(lo), get(hi);
    v = lo | (std::uint32_t{hi} << 16);
  }
  // anki-overdrive.md: floats are IEEE-754 single precision, little-endian.
  void get(float& v) {
    std::uint32_t bits = 0;
    get(bits);
    v = std::bit_cast<float>(bits);
  }
  template <class E>
  requires std::is_enum_v<E>
  void get(E& v) {  // any byte is kept, also one outside the enum
    v = static_cast<E>(next());
  }
  template <class T>
  void get(std::optional<T>& v) {
    if (long_form_) get(v.emplace());
  }
  void get(LightChannel& c) {
    get(c.channel), get(c.effect), get(c.start), get(c.end), get(c.cycles_per_10s);
  }
  template <class T, std::size_t N>
  void get(std::array<T, N>& a) {
    for (auto& x : a) get(x);
  }

 private:
  std::uint8_t next() {
    std::uint8_t b = 0;
    get(b);
    return b;
  }

  std::span<const std::uint8_t> frame_;
  std::size_t at_ = 2;  // after [size][id]
  bool long_form_;
};

// Writes a frame [size][id][payload]; finish() fills in the size byte.
class Writer {
 public:
  Writer(std::uint8_t id, bool long_form) : long_form_(long_form) {
    frame_.bytes[1] = id;
    frame_.length = 2;
  }

  void put(std::uint8_t v) {
    assert(frame_.length < Frame::kMax);
    frame_.bytes[frame_.length++] = v;
  }
  void put(bool v) { put(static_cast<std::uint8_t>(v ? 1 : 0)); }
  void put(std::int8_t v) { put(static_cast<std::uint8_t>(v)); }
  void put(std::uint16_t v) {
    put(static_cast<std::uint8_t>(v & 0xff)), put(static_cast<std::uint8_t>(v >> 8));
  }
  void put(std::int16_t v) { put(static_cast<std::uint16_t>(v)); }
  void put(std::uint32_t v) {
    put(static_cast<std::uint16_t>(v & 0xffff)), put(static_cast<std::uint16_t>(v >> 16));
  }
  void put(float v) { put(std::bit_cast<std::uint32_t>(v)); }
  template <class E>
  requires std::is_enum_v<E>
  void put(E v) { put(static_cast<std::uint8_t>(v)); }
  // In the long form every optional field is written; one left empty goes out as zero.
  template <class T>
  void put(const std::optional<T>& v) {
    if (long_form_) put(v.value_or(T{}));
  }
  void put(const LightChannel& c) {
    put(c.channel), put(c.effect), put(c.start), put(c.end), put(c.cycles_per_10s);
  }
  template <class T, std::size_t N>
  void put(const std::array<T, N>& a) {
    for (const auto& x : a) put(x);
  }

  Frame finish() {
    frame_.bytes[0] = static_cast<std::uint8_t>(frame_.length - 1);
    return frame_;
  }

 private:
  Frame frame_;
  bool long_form_;
};

// The size bytes (= frame length − 1) a message may have. Most have one. A few have a shorter
// and a longer form told apart by the size byte alone: optional fields are in the longer one;
// bytes past the last field (newer firmware's extras) are accepted and not kept.
struct Sizes {
  std::uint8_t shorter;
  std::uint8_t longer;
};

struct Layout {
  std::uint8_t id;
  std::string_view name;  // kebab-case, stable: scripts and recordings use it
  Sizes sizes;
};

// A message's fields in wire order.
template <class T, auto... Field>
struct Fields {
  static void read([[maybe_unused]] Reader& r, [[maybe_unused]] T& m) { (r.get(m.*Field), ...); }
  static void write([[maybe_unused]] Writer& w, [[maybe_unused]] const T& m) {
    (w.put(m.*Field), ...);
  }
  // Written long as soon as one optional field is set.
  static bool longForm([[maybe_unused]] const T& m) { return (isSet(m.*Field) || ... || false); }

 private:
  template <class F>
  static bool isSet(const F& f) {
    if constexpr (IsOptional<F>::value) {
      return f.has_value();
    } else {
      return false;
    }
  }
};

template <class T>
struct Spec;

// ---- controller → vehicle (anki-overdrive.md "Controller → vehicle"; seed 000 §4.3.4) ----

template <>
struct Spec<Disconnect> : Fields<Disconnect> {
  static constexpr Layout layout{id::kDisconnect, "disconnect", {1, 1}};
};
template <>
struct Spec<PingRequest> : Fields<PingRequest> {  // seed 000 §4.3.4.2: 01 16
  static constexpr Layout layout{id::kPingRequest, "ping-request", {1, 1}};
};
template <>
struct Spec<VersionRequest> : Fields<VersionRequest> {  // seed 000 §4.3.4.8: 01 18
  static constexpr Layout layout{id::kVersionRequest, "version-request", {1, 1}};
};
template <>
struct Spec<BatteryRequest> : Fields<BatteryRequest> {  // seed 000 §4.3.4.7: 01 1a
  static constexpr Layout layout{id::kBatteryRequest, "battery-request", {1, 1}};
};
template <>
struct Spec<SetLights> : Fields<SetLights, &SetLights::mask> {
  static constexpr Layout layout{id::kSetLights, "set-lights", {2, 2}};
};
// seed 000 §4.3.4.3: i16 speed, i16 accel; anki-overdrive.md: + u8 respect limit (size 6); newer
// firmware takes a trailing byte (size 7) that we accept and do not model.
template <>
struct Spec<SetSpeed>
    : Fields<SetSpeed, &SetSpeed::speed_mm_s, &SetSpeed::accel_mm_s2, &SetSpeed::respect_limit> {
  static constexpr Layout layout{id::kSetSpeed, "set-speed", {6, 7}};
};
// seed 000 §4.3.4.4; anki-overdrive.md: + u8 hop intent, u8 tag (size 11).
template <>
struct Spec<ChangeLane>
    : Fields<ChangeLane, &ChangeLane::h_speed_mm_s, &ChangeLane::h_accel_mm_s2,
             &ChangeLane::offset_mm, &ChangeLane::hop_intent, &ChangeLane::tag> {
  static constexpr Layout layout{id::kChangeLane, "change-lane", {11, 11}};
};
template <>
struct Spec<CancelLaneChange> : Fields<CancelLaneChange> {
  static constexpr Layout layout{id::kCancelLaneChange, "cancel-lane-change", {1, 1}};
};
// seed 000 §4.3.4.5 writes size 3 in its example, but an f32 payload makes size 5
// (anki-overdrive.md).
template <>
struct Spec<SetOffset> : Fields<SetOffset, &SetOffset::offset_mm> {
  static constexpr Layout layout{id::kSetOffset, "set-offset", {5, 5}};
};
template <>
struct Spec<Turn> : Fields<Turn, &Turn::type, &Turn::trigger> {  // seed 000 §4.3.4.6
  static constexpr Layout layout{id::kTurn, "turn", {3, 3}};
};
// anki-overdrive.md: u8 channel count, then always 3 channel slots (size 17).
template <>
struct Spec<LightsPattern>
    : Fields<LightsPattern, &LightsPattern::channel_count, &LightsPattern::channels> {
  static constexpr Layout layout{id::kLightsPattern, "lights-pattern", {17, 17}};
};
template <>
struct Spec<SetConfig>
    : Fields<SetConfig, &SetConfig::super_code_parse_mask, &SetConfig::track_material> {
  static constexpr Layout layout{id::kSetConfig, "set-config", {3, 3}};
};
template <>
struct Spec<SdkMode> : Fields<SdkMode, &SdkMode::on, &SdkMode::flags> {  // seed 000 §4.3.4.1
  static constexpr Layout layout{id::kSdkMode, "sdk-mode", {3, 3}};
};

// ---- vehicle → controller (anki-overdrive.md "Vehicle → controller"; seed 000 §4.3.5) ----

template <>
struct Spec<PingResponse> : Fields<PingResponse> {
  static constexpr Layout layout{id::kPingResponse, "ping-response", {1, 1}};
};
// anki-overdrive.md: some firmware sends 4 payload bytes; only the first u16 is the version.
template <>
struct Spec<VersionResponse> : Fields<VersionResponse, &VersionResponse::version> {
  static constexpr Layout layout{id::kVersionResponse, "version-response", {3, 5}};
};
template <>
struct Spec<BatteryResponse> : Fields<BatteryResponse, &BatteryResponse::millivolts> {
  static constexpr Layout layout{id::kBatteryResponse, "battery-response", {3, 3}};
};
// seed 000 §4.3.5.3 (drive-sdk's packed struct).
template <>
struct Spec<PositionUpdate>
    : Fields<PositionUpdate, &PositionUpdate::location_id, &PositionUpdate::piece_id,
             &PositionUpdate::offset_mm, &PositionUpdate::speed_mm_s,
             &PositionUpdate::parsing_flags, &PositionUpdate::last_recv_lane_change_id,
             &PositionUpdate::last_exec_lane_change_id,
             &PositionUpdate::last_desired_lane_change_speed_mm_s,
             &PositionUpdate::last_desired_speed_mm_s> {
  static constexpr Layout layout{id::kPositionUpdate, "position-update", {16, 16}};
};
// seed 000 §4.3.5.4 (size 17). anki-overdrive.md "Firmware variants": before firmware 0x2b6e a
// u8 driving direction follows the offset (size 18) and every later field moves by one byte.
template <>
struct Spec<TransitionUpdate>
    : Fields<TransitionUpdate, &TransitionUpdate::piece_idx, &TransitionUpdate::prev_piece_idx,
             &TransitionUpdate::offset_mm, &TransitionUpdate::driving_direction,
             &TransitionUpdate::last_recv_lane_change_id,
             &TransitionUpdate::last_exec_lane_change_id,
             &TransitionUpdate::last_desired_lane_change_speed_mm_s,
             &TransitionUpdate::average_follow_line_drift_px,
             &TransitionUpdate::had_lane_change_activity, &TransitionUpdate::uphill_counter,
             &TransitionUpdate::downhill_counter, &TransitionUpdate::left_wheel_distance_cm,
             &TransitionUpdate::right_wheel_distance_cm> {
  static constexpr Layout layout{id::kTransitionUpdate, "transition-update", {17, 18}};
};
// seed 000 §4.3.5.5's struct ends after mm_since_last_transition_bar (the older size 10);
// anki-overdrive.md: newer firmware adds u16 mm since last intersection code (size 12).
template <>
struct Spec<IntersectionUpdate>
    : Fields<IntersectionUpdate, &IntersectionUpdate::piece_idx, &IntersectionUpdate::offset_mm,
             &IntersectionUpdate::intersection_code, &IntersectionUpdate::is_exiting,
             &IntersectionUpdate::mm_since_last_transition_bar,
             &IntersectionUpdate::mm_since_last_intersection_code> {
  static constexpr Layout layout{id::kIntersectionUpdate, "intersection-update", {10, 12}};
};
template <>
struct Spec<Delocalized> : Fields<Delocalized> {  // seed 000 §4.3.5.6
  static constexpr Layout layout{id::kDelocalized, "delocalized", {1, 1}};
};
template <>
struct Spec<OffsetUpdate>
    : Fields<OffsetUpdate, &OffsetUpdate::offset_mm, &OffsetUpdate::lane_change_id> {
  static constexpr Layout layout{id::kOffsetUpdate, "offset-update", {6, 6}};
};
template <>
struct Spec<SpeedUpdate> : Fields<SpeedUpdate, &SpeedUpdate::desired_mm_s,
                                  &SpeedUpdate::accel_mm_s2, &SpeedUpdate::actual_mm_s> {
  static constexpr Layout layout{id::kSpeedUpdate, "speed-update", {7, 7}};
};
// seed 000 §4.3.5.7: on track, on charger (size 3); anki-overdrive.md: newer firmware adds low
// battery and fully charged (size 5).
template <>
struct Spec<CarStatus> : Fields<CarStatus, &CarStatus::on_track, &CarStatus::on_charger,
                                &CarStatus::low_battery, &CarStatus::fully_charged> {
  static constexpr Layout layout{id::kCarStatus, "car-status", {3, 5}};
};
// anki-overdrive.md gives size byte 15, but its fields end at @14 (a 15-byte frame, size 14).
// Decision: read both; write size 15 with the unexplained last byte @15 as zero.
template <>
struct Spec<LaneChangeUpdate>
    : Fields<LaneChangeUpdate, &LaneChangeUpdate::current_offset_mm,
             &LaneChangeUpdate::target_offset_mm, &LaneChangeUpdate::h_speed_mm_s,
             &LaneChangeUpdate::v_speed_mm_s, &LaneChangeUpdate::lane_change_id> {
  static constexpr Layout layout{id::kLaneChangeUpdate, "lane-change-update", {14, 15}};
  static void write(Writer& w, const LaneChangeUpdate& m) {
    Fields::write(w, m);
    w.put(std::uint8_t{0});
  }
};
template <>
struct Spec<AutoRecoveryEntered> : Fields<AutoRecoveryEntered> {
  static constexpr Layout layout{id::kAutoRecoveryEntered, "auto-recovery-entered", {1, 1}};
};
template <>
struct Spec<AutoRecoverySucceeded> : Fields<AutoRecoverySucceeded> {
  static constexpr Layout layout{id::kAutoRecoverySucceeded, "auto-recovery-succeeded", {1, 1}};
};
template <>
struct Spec<Collision> : Fields<Collision, &Collision::side, &Collision::front_back> {
  static constexpr Layout layout{id::kCollision, "collision", {3, 3}};
};
template <>
struct Spec<CycleOvertime> : Fields<CycleOvertime, &CycleOvertime::count,
                                    &CycleOvertime::average_us, &CycleOvertime::max_us> {
  static constexpr Layout layout{id::kCycleOvertime, "cycle-overtime", {11, 11}};
};

// ---- dispatch by id ----

constexpr std::size_t kKnownKinds = std::variant_size_v<Message> - 1;  // all but Unknown
static_assert(std::is_same_v<std::variant_alternative_t<kKnownKinds, Message>, Unknown>,
              "Unknown must stay the last alternative of Message");

template <std::size_t I>
using Kind = std::variant_alternative_t<I, Message>;

using Decoded = Result<Message, DecodeError>;

// The message is emplaced into the returned result (NRVO) and filled there by a Reader that
// stays in registers: no copy of a freshly written struct (measured: ~2× faster than a copy).
template <class T>
Decoded readFrame(std::span<const std::uint8_t> frame) {
  constexpr Sizes sizes = Spec<T>::layout.sizes;
  Decoded out{Message{}};  // an empty alternative: nothing to copy
  Reader reader(frame, sizes.shorter != sizes.longer && frame[0] == sizes.longer);
  Spec<T>::read(reader, out.value().template emplace<T>());
  return out;
}

template <class T>
Frame writeFrame(const T& m) {
  Writer writer(Spec<T>::layout.id, Spec<T>::longForm(m));
  Spec<T>::write(writer, m);
  return writer.finish();
}

struct Entry {
  Layout layout{0, {}, {0, 0}};
  Decoded (*read)(std::span<const std::uint8_t>) = nullptr;  // nullptr: the id is not known
};

// kById[id]: what the id is and how to read it, built from the Specs above.
constexpr std::array<Entry, 256> kById = [] {
  std::array<Entry, 256> table{};
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((table[Spec<Kind<I>>::layout.id] = Entry{Spec<Kind<I>>::layout, &readFrame<Kind<I>>}), ...);
  }
  (std::make_index_sequence<kKnownKinds>{});
  return table;
}();

// Every Spec must have its own id: a clash would silently shadow a message.
constexpr bool idsAreDistinct() {
  std::array<bool, 256> seen{};
  bool distinct = true;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((distinct = distinct && !std::exchange(seen[Spec<Kind<I>>::layout.id], true)), ...);
  }
  (std::make_index_sequence<kKnownKinds>{});
  return distinct;
}
static_assert(idsAreDistinct(), "two message kinds share one id");

Decoded fail(DecodeError::Kind kind, std::uint8_t id, std::size_t expected, std::size_t received) {
  return Unexpected{DecodeError{kind, id, expected, received}};
}

std::string hexId(std::uint8_t id) {
  static constexpr char kDigits[] = "0123456789abcdef";
  return {'0', 'x', kDigits[id >> 4], kDigits[id & 0x0f]};
}

std::string bytes(std::size_t n) {
  return std::to_string(n) + (n == 1 ? " byte" : " bytes");
}

std::string idText(std::uint8_t id) {
  const auto& e = kById[id];
  return "message " + hexId(id) +
         (e.read ? " (" + std::string(e.layout.name) + ")" : std::string());
}

}  // namespace

Result<Message, DecodeError> decode(std::span<const std::uint8_t> frame) {
  using K = DecodeError::Kind;
  const std::size_t n = frame.size();
  if (n == 0) return fail(K::Empty, 0, 2, 0);
  const std::uint8_t id = n >= 2 ? frame[1] : 0;
  if (n > Frame::kMax) return fail(K::TooBig, id, Frame::kMax, n);
  // anki-overdrive.md "Frame": the size byte counts the id and the payload (= length − 1).
  if (std::size_t{frame[0]} != n - 1) {
    return fail(K::SizeMismatch, id, std::size_t{frame[0]} + 1, n);
  }
  if (n < 2) return fail(K::TooShort, 0, 2, n);  // a lone size byte 00: no id at all

  const Entry& entry = kById[id];
  if (entry.read == nullptr) {  // anki-overdrive.md **Decision**: unknown ids are kept whole
    Unknown unknown{.id = id, .raw = {}};
    std::memcpy(unknown.raw.bytes.data(), frame.data(), n);
    unknown.raw.length = static_cast<std::uint8_t>(n);
    return Message{unknown};
  }
  const std::uint8_t size = frame[0];
  const auto [shorter, longer] = entry.layout.sizes;
  if (size > longer) return fail(K::TooLong, id, std::size_t{longer} + 1, n);
  // Between an older and a newer form counts as a cut-short newer form.
  if (size != shorter && size != longer) {
    return fail(K::TooShort, id, std::size_t{size < shorter ? shorter : longer} + 1, n);
  }
  return entry.read(frame);
}

Frame encode(const Message& message) {
  return std::visit(
      []<class T>(const T& m) -> Frame {
        if constexpr (std::is_same_v<T, Unknown>) {
          if (m.raw.length > 0) return m.raw;
          return Writer(m.id, false).finish();  // an Unknown built by hand without bytes
        } else {
          return writeFrame(m);
        }
      },
      message);
}

std::string_view name(const Message& message) {
  return std::visit(
      []<class T>(const T&) -> std::string_view {
        if constexpr (std::is_same_v<T, Unknown>) {
          return "unknown";
        } else {
          return Spec<T>::layout.name;
        }
      },
      message);
}

std::uint8_t messageId(const Message& message) {
  return std::visit(
      []<class T>(const T& m) -> std::uint8_t {
        if constexpr (std::is_same_v<T, Unknown>) {
          return m.id;
        } else {
          return Spec<T>::layout.id;
        }
      },
      message);
}

std::string DecodeError::message() const {
  switch (kind) {
    case Kind::Empty:
      return "empty frame: no bytes received, a frame needs at least a size byte and an id";
    case Kind::TooBig:
      return idText(id) + " is " + bytes(received) + " long, more than the " + bytes(Frame::kMax) +
             " a frame may have";
    case Kind::SizeMismatch:
      return (received < 2 ? std::string("frame without an id") : idText(id)) +
             ": its size byte says " + bytes(expected) + " but " + bytes(received) + " arrived";
    case Kind::TooShort:
      if (received < 2) {
        return "frame without an id: " + bytes(received) + " received, a frame needs at least " +
               bytes(expected) + " (size and id)";
      }
      return idText(id) + " is too short: " + bytes(received) + " received, its layout needs " +
             bytes(expected);
    case Kind::TooLong:
      return idText(id) + " is too long: " + bytes(received) + " received, its longest layout is " +
             bytes(expected);
  }
  return "decode error " + std::to_string(static_cast<int>(kind));
}

}  // namespace pitwall::anki
