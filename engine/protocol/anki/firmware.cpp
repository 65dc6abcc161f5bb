#include "engine/protocol/anki/firmware.hpp"

#include <cctype>

namespace pitwall::anki {

Result<std::uint16_t, std::string> parseFirmware(std::string_view text) {
  std::string_view digits = text;
  if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X'))
    digits.remove_prefix(2);
  unsigned value = 0;
  bool ok = !digits.empty() && digits.size() <= 4;
  for (char c : digits) {
    if (!ok || !std::isxdigit(static_cast<unsigned char>(c))) {
      ok = false;
      break;
    }
    value = value * 16 +
            static_cast<unsigned>(std::isdigit(static_cast<unsigned char>(c))
                                      ? c - '0'
                                      : std::tolower(static_cast<unsigned char>(c)) - 'a' + 10);
  }
  if (!ok || value == 0) {
    std::string shown(text.substr(0, 40));
    for (char& c : shown)
      if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
    return Unexpected(
        std::string("firmware '") + shown +
        "' is not a version: give it in hex, 1 to ffff, as `pitwall scan` shows it, e.g. "
        "0x266e (2016: 19-byte transition update) or 0x2b70 (the default)");
  }
  return static_cast<std::uint16_t>(value);
}

}  // namespace pitwall::anki
