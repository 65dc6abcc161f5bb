// The accepted range of every controller→vehicle command (anki-overdrive.md "Rates and limits",
// "Controller → vehicle"). Vehicle→controller messages are reports, never refused.
#include "engine/protocol/anki/limits.hpp"

#include <charconv>
#include <cmath>
#include <string_view>
#include <type_traits>

namespace pitwall::anki::limits {
namespace {

using Verdict = std::optional<std::string>;

std::string text(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v < 0 ? "-inf" : "inf";
  char buf[32];
  return {buf, std::to_chars(buf, buf + sizeof buf, v).ptr};
}

std::string withUnit(std::string value, std::string_view unit) {
  if (!unit.empty()) (value += ' ') += unit;
  return value;
}

// "speed 2000 mm/s is out of range 0..1500 mm/s"
Verdict range(std::string_view field, double value, double min, double max,
              std::string_view unit = {}) {
  // NaN fails both comparisons, so test for "inside" rather than for "outside".
  if (value >= min && value <= max) return std::nullopt;
  return std::string(field) + " " + withUnit(text(value), unit) + " is out of range " + text(min) +
         ".." + withUnit(text(max), unit);
}

// seed 000 §4.3.4.4: the offset range is where the road is, which the sentence says.
Verdict offset(double value) {
  auto v = range("offset", value, kOffsetMin, kOffsetMax, "mm");
  if (v) *v += " (beyond it the car leaves the road)";
  return v;
}

Verdict firstOf(std::initializer_list<Verdict> verdicts) {
  for (const auto& v : verdicts) {
    if (v) return v;
  }
  return std::nullopt;
}

Verdict check(const SetSpeed& m) {
  return firstOf({range("speed", m.speed_mm_s, kSpeedMin, kSpeedMax, "mm/s"),
                  range("accel", m.accel_mm_s2, kAccelMin, kAccelMax, "mm/s²")});
}

Verdict check(const ChangeLane& m) {
  return firstOf(
      {range("lane-change speed", m.h_speed_mm_s, kLaneSpeedMin, kLaneSpeedMax, "mm/s"),
       range("lane-change accel", m.h_accel_mm_s2, kLaneAccelMin, kLaneAccelMax, "mm/s²"),
       offset(m.offset_mm)});
}

Verdict check(const SetOffset& m) {
  return offset(m.offset_mm);
}

// anki-overdrive.md: type 0 none … 4 U-turn jump; trigger 0 immediate, 1 at next intersection.
Verdict check(const Turn& m) {
  return firstOf(
      {range("turn type", static_cast<int>(m.type), 0, static_cast<int>(TurnType::UTurnJump)),
       range("turn trigger", static_cast<int>(m.trigger), 0,
             static_cast<int>(TurnTrigger::Intersection))});
}

// anki-overdrive.md "Lights pattern": ≤3 channels, channel 0..5, effect 0..4, intensity 0..14.
// Slots beyond channel_count are not looked at: the car ignores them.
Verdict check(const LightsPattern& m) {
  if (auto v = range("channel count", m.channel_count, 1, static_cast<double>(m.channels.size()))) {
    return v;
  }
  for (std::size_t i = 0; i < m.channel_count; ++i) {
    const auto& c = m.channels[i];
    const std::string slot = "slot " + std::to_string(i + 1) + " ";
    if (auto v = firstOf({range(slot + "channel", c.channel, 0, kLightChannelMax),
                          range(slot + "effect", c.effect, 0, kLightEffectMax),
                          range(slot + "start intensity", c.start, 0, kLightIntensityMax),
                          range(slot + "end intensity", c.end, 0, kLightIntensityMax)})) {
      return v;
    }
  }
  return std::nullopt;
}

Verdict check(const SetConfig& m) {
  return range("track material", m.track_material, 0, kTrackMaterialMax);
}

// anki-overdrive.md: "Never send 0x3a." A raw frame with that id is refused.
Verdict check(const Unknown& m) {
  if (m.id != 0x3a) return std::nullopt;
  return std::string("message id 0x3a must never be sent to a car (anki-overdrive.md)");
}

// Everything else (requests without payload, set-lights, sdk-mode, and every vehicle→controller
// report) has no range to break.
template <class T>
Verdict check(const T&) {
  return std::nullopt;
}

}  // namespace

std::optional<std::string> validate(const Message& message) {
  return std::visit([](const auto& m) { return check(m); }, message);
}

}  // namespace pitwall::anki::limits
