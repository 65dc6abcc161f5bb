#pragma once
// Alphabot requests from words, for `pitwall encode alphabot …`: "drive 50 -10",
// "toggles collisionAvoidance,positioning", "anchor 1 100 200", … (commandForms() lists them).
// Numbers are decimal or 0x…; an out-of-range value is refused with the accepted range.
#include <string>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/protocol/alphabot/messages.hpp"

namespace pitwall::alphabot {

Result<Request, std::string> parseRequest(const std::vector<std::string>& words);
std::vector<std::string> commandForms();

// Range checks shared with the Lua object (validate at the edge): an empty string when `value`
// fits, else "WHAT VALUE is out of range LO..HI".
std::string checkRange(const char* what, long long value, long long lo, long long hi);
constexpr long long kDriveMin = -128, kDriveMax = 127;      // i8 speed and steer
constexpr long long kCoordMin = -32768, kCoordMax = 32767;  // i16 cm
constexpr long long kSizeMin = 1, kSizeMax = 65535;         // u16 cm, an empty obstacle is refused
constexpr long long kDegreeMin = -360, kDegreeMax = 360;    // relative to the heading
constexpr long long kIdMin = 0, kIdMax = 255;               // u8 anchor / obstacle id

}  // namespace pitwall::alphabot
