#include "engine/protocol/alphabot/toggles.hpp"

#include <array>

namespace pitwall::alphabot {
namespace {

// alphabot.md §3, toggle: byte 1 bits 7..2 settings (1..0 unused), byte 2 bits 7..0 logging.
constexpr std::array<ToggleBit, 14> kBits = {{
    {"compassCalibration", false, 7},
    {"invite", false, 6},
    {"positioning", false, 5},
    {"collisionAvoidance", false, 4},
    {"navigationMode", false, 3},
    {"exploreMode", false, 2},
    {"logPosition", true, 7},
    {"logObstacleDistance", true, 6},
    {"logPath", true, 5},
    {"logCompass", true, 4},
    {"logAnchorDistances", true, 3},
    {"logWheelSpeed", true, 2},
    {"logAccelerometer", true, 1},
    {"logGyroscope", true, 0},
}};

}  // namespace

std::span<const ToggleBit> toggleBits() {
  return kBits;
}

const ToggleBit* findToggle(std::string_view name) {
  for (const auto& b : kBits)
    if (name == b.name) return &b;
  return nullptr;
}

std::string toggleNames() {
  std::string s;
  for (const auto& b : kBits) s += (s.empty() ? "" : ", ") + std::string(b.name);
  return s;
}

bool isSet(const Toggles& t, const ToggleBit& bit) {
  std::uint8_t byte = bit.logging ? t.logging : t.settings;
  return (byte >> bit.bit) & 1;
}

void setBit(Toggles& t, const ToggleBit& bit, bool on) {
  std::uint8_t& byte = bit.logging ? t.logging : t.settings;
  auto mask = static_cast<std::uint8_t>(1u << bit.bit);
  byte = on ? static_cast<std::uint8_t>(byte | mask) : static_cast<std::uint8_t>(byte & ~mask);
}

}  // namespace pitwall::alphabot
