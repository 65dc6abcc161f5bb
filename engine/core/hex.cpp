#include "engine/core/hex.hpp"

namespace pitwall {

namespace {
constexpr char kDigits[] = "0123456789abcdef";

int digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}
}  // namespace

std::string hexByte(std::uint8_t b) {
  return {'0', 'x', kDigits[b >> 4], kDigits[b & 0x0f]};
}

std::string toHex(std::span<const std::uint8_t> bytes, std::string_view separator) {
  std::string out;
  out.reserve(bytes.size() * (2 + separator.size()));
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (i) out += separator;
    out += kDigits[bytes[i] >> 4];
    out += kDigits[bytes[i] & 0x0f];
  }
  return out;
}

Result<std::vector<std::uint8_t>, std::string> fromHex(std::string_view text) {
  if (text.size() % 2)
    return Unexpected{"odd number of hex digits (" + std::to_string(text.size()) + ")"};
  std::vector<std::uint8_t> out;
  out.reserve(text.size() / 2);
  for (std::size_t i = 0; i < text.size(); i += 2) {
    int hi = digit(text[i]), lo = digit(text[i + 1]);
    if (hi < 0 || lo < 0)
      return Unexpected{"\"" + std::string(text.substr(i, 2)) + "\" is not a hex byte"};
    out.push_back(static_cast<std::uint8_t>(hi * 16 + lo));
  }
  return out;
}

}  // namespace pitwall
