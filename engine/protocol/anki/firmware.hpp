#pragma once
// Firmware families (anki-overdrive.md "Firmware variants"; docs/simulator.md "Firmware
// families"): which layouts a car of a given firmware version sends. The codec reads every layout
// by its size byte, so a controller needs no choice; the simulator plays a family by its version.
#include <cstdint>
#include <string>
#include <string_view>

#include "engine/core/result.hpp"

namespace pitwall::anki {

// Firmware older than this sends the 19-byte transition update (a driving direction after the
// offset), the 10-byte intersection update and the speed update with one field (IBM's 0x266e).
inline constexpr std::uint16_t kFirmwareNewLayouts = 0x2b6e;
// The version simulated cars answer unless told otherwise: of the newer family.
inline constexpr std::uint16_t kFirmwareDefault = 0x2b70;

inline bool olderLayouts(std::uint16_t version) {
  return version < kFirmwareNewLayouts;
}

// A version as people write it, in hex as `pitwall scan` shows it: "0x266e", "266E", "2b70".
// An error names the text and what to give.
Result<std::uint16_t, std::string> parseFirmware(std::string_view text);

}  // namespace pitwall::anki
