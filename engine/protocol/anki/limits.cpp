// The accepted range of every controller→vehicle command (anki-overdrive.md "Rates and limits",
// "Controller → vehicle"). Vehicle→controller messages are reports, never refused.
#include "engine/protocol/anki/limits.hpp"

#include "engine/core/numbers.hpp"

#include <string_view>

namespace pitwall::anki::limits {
namespace {

using Verdict = std::optional<std::string>;

// seed 000 §4.3.4.4: the offset range is where the road is, which the sentence says.
Verdict offset(double value) {
  auto v = checkRange("offset", value, kOffsetMin, kOffsetMax, "mm");
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
  return firstOf({checkRange("speed", m.speed_mm_s, kSpeedMin, kSpeedMax, "mm/s"),
                  checkRange("acceleration", m.accel_mm_s2, kAccelMin, kAccelMax, "mm/s²")});
}

Verdict check(const ChangeLane& m) {
  return firstOf(
      {checkRange("lane-change speed", m.h_speed_mm_s, kLaneSpeedMin, kLaneSpeedMax, "mm/s"),
       checkRange("lane-change acceleration", m.h_accel_mm_s2, kLaneAccelMin, kLaneAccelMax,
                  "mm/s²"),
       offset(m.offset_mm)});
}

Verdict check(const SetOffset& m) {
  return offset(m.offset_mm);
}

// anki-overdrive.md: type 0 none … 4 U-turn jump; trigger 0 immediate, 1 at next intersection.
Verdict check(const Turn& m) {
  return firstOf(
      {checkRange("turn type", static_cast<int>(m.type), 0, static_cast<int>(TurnType::UTurnJump)),
       checkRange("turn trigger", static_cast<int>(m.trigger), 0,
                  static_cast<int>(TurnTrigger::Intersection))});
}

// anki-overdrive.md "Lights pattern": ≤3 channels, channel 0..5, effect 0..4, intensity 0..14.
// Slots beyond channel_count are not looked at: the car ignores them.
Verdict check(const LightsPattern& m) {
  if (auto v =
          checkRange("channel count", m.channel_count, 1, static_cast<double>(m.channels.size()))) {
    return v;
  }
  for (std::size_t i = 0; i < m.channel_count; ++i) {
    const auto& c = m.channels[i];
    const std::string slot = "slot " + std::to_string(i + 1) + " ";
    if (auto v = firstOf({checkRange(slot + "channel", c.channel, 0, kLightChannelMax),
                          checkRange(slot + "effect", c.effect, 0, kLightEffectMax),
                          checkRange(slot + "start intensity", c.start, 0, kLightIntensityMax),
                          checkRange(slot + "end intensity", c.end, 0, kLightIntensityMax)})) {
      return v;
    }
  }
  return std::nullopt;
}

Verdict check(const SetConfig& m) {
  return checkRange("track material", m.track_material, 0, kTrackMaterialMax);
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
