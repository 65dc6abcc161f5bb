#pragma once
// What an Anki car advertises (anki-overdrive.md "Advertisement").
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/result.hpp"

namespace pitwall::anki {

inline constexpr std::string_view kServiceUuid = "be15beef-6186-407e-8381-0bd89c4d8df4";
inline constexpr std::string_view kReadCharUuid = "be15bee0-6186-407e-8381-0bd89c4d8df4";
inline constexpr std::string_view kWriteCharUuid = "be15bee1-6186-407e-8381-0bd89c4d8df4";
inline constexpr std::uint16_t kManufacturerKey = 0xEFBE;  // "BE EF" read as little-endian

struct ManufacturerData {
  std::uint16_t product_id = 0xBEEF;
  std::uint8_t model_id = 0;
  std::uint32_t identifier = 0;
};
// 8 raw bytes [BE EF, reserved, model, id(4, big-endian)].
Result<ManufacturerData, std::string> parseManufacturerData(std::span<const std::uint8_t> raw);
// BlueZ's shape: company key (0xEFBE, also accepted as the signed −4162) + the 6 bytes after it.
Result<ManufacturerData, std::string> parseManufacturerData(int key,
                                                            std::span<const std::uint8_t> value);

struct LocalName {
  bool full_battery = false;  // state bit 0x10
  bool low_battery = false;   // state bit 0x20
  bool on_charger = false;    // state bit 0x40
  std::uint16_t version = 0;
  std::string user_name;
};
// Never fails: short input gives what could be read (a name cut short by BlueZ is common).
LocalName parseLocalName(std::span<const std::uint8_t> raw);

// "Groundshock", …; unknown ids give "model-<n>".
std::string modelName(std::uint8_t model_id);
// A car's default name from its model: "groundshock", or "groundshock-2" when that is in `taken`
// (simulated cars, and real cars whose user name BlueZ does not pass on).
std::string uniqueCarName(std::uint8_t model_id, const std::vector<std::string>& taken);

}  // namespace pitwall::anki
