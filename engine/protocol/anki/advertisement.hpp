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

// Whether bytes have the shape of an Anki local name rather than a plain text name: at least 8
// bytes, a state byte with no bits but 0x10/0x20/0x40, and the first reserved byte (3) a control
// character — 0x01 on the real cars captured (their other reserved bytes are spaces and
// letters), zero in drive-sdk's description, kNameFiller from an emulated one (localNameText).
// A text name has a printable character there.
bool isAnkiLocalName(std::span<const std::uint8_t> raw);

// What an emulated car puts in the reserved bytes, which a real car leaves zero: a stack that
// takes the local name as a string (BlueZ's LEAdvertisement1.LocalName is a D-Bus string: UTF-8,
// no NUL) cannot carry zeros.
inline constexpr std::uint8_t kNameFiller = 0x01;
// A local name is at most 20 bytes: 8 before the user name, so 12 for it.
inline constexpr std::size_t kMaxUserNameBytes = 12;
// Why `name` cannot be advertised as a car's user name, "" when it can: UTF-8 without control
// characters, 1..kMaxUserNameBytes bytes.
std::string userNameProblem(std::string_view name);
// The local name as text with the layout of the binary one — state byte, version little-endian,
// kNameFiller × 5, user name — so that clients that read a car's state from the name's first
// byte (py-drivesdk skips a car whose byte 0 has the on-charger bit) take it for a car. Refused
// with the reason when a byte would be NUL or not a character on its own: a state with no bit
// set, a version byte 0 or above 0x7f, a user name userNameProblem() refuses.
Result<std::string, std::string> localNameText(const LocalName& name);

// "Groundshock", …; unknown ids give "model-<n>".
std::string modelName(std::uint8_t model_id);
// A car's default name from its model: "groundshock", or "groundshock-2" when that is in `taken`
// (simulated cars, and real cars whose user name BlueZ does not pass on).
std::string uniqueCarName(std::uint8_t model_id, const std::vector<std::string>& taken);

}  // namespace pitwall::anki
