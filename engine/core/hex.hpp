#pragma once
// Bytes as hex text and back: the one formatter for log lines, JSON fields, the CLI and the MQTT
// frame event (lowercase digits).
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/result.hpp"

namespace pitwall {

// "0x27"
std::string hexByte(std::uint8_t b);
// "06 24 e8" (separator " "), "0624e8" (separator "").
std::string toHex(std::span<const std::uint8_t> bytes, std::string_view separator = " ");
// Exactly pairs of hex digits, either case, nothing else: "0624E8" → 06 24 e8. An error names the
// problem: an odd number of digits, or the pair that is not hex.
Result<std::vector<std::uint8_t>, std::string> fromHex(std::string_view digits);

}  // namespace pitwall
