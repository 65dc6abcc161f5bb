#pragma once
// The accepted range of every controller→vehicle command. Validation happens at the edge (Lua,
// CLI, later MQTT): an out-of-range command gets an error sentence and nothing is sent.
#include <optional>
#include <string>

#include "engine/protocol/anki/messages.hpp"

namespace pitwall::anki::limits {

inline constexpr int kSpeedMin = 0, kSpeedMax = 1500;           // mm/s
inline constexpr int kAccelMin = 0, kAccelMax = 25000;          // mm/s²
inline constexpr int kLaneSpeedMin = 0, kLaneSpeedMax = 1500;   // mm/s
inline constexpr int kLaneAccelMin = 0, kLaneAccelMax = 25000;  // mm/s²
// mm from road centre: seed 000 §4.3.4.4, beyond ±70 mm the car leaves the road
inline constexpr double kOffsetMin = -70.0, kOffsetMax = 70.0;
inline constexpr int kLightChannelMax = 5, kLightEffectMax = 4, kLightIntensityMax = 14;
inline constexpr int kTrackMaterialMax = 1;

// nullopt when the message may be sent; otherwise one sentence naming the field, the value and
// the accepted range, e.g. "speed 2000 mm/s is out of range 0..1500 mm/s".
std::optional<std::string> validate(const Message& message);

}  // namespace pitwall::anki::limits
