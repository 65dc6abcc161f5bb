#include "engine/core/printable.hpp"

#include <cstdio>

namespace pitwall {

std::size_t utf8Length(std::string_view s) {
  auto c = static_cast<unsigned char>(s[0]);
  // lead bytes: C2–DF of 2, E0–EF of 3, F0–F4 of 4; F5–FF and C0, C1 never lead
  std::size_t n = c >= 0xf0 && c <= 0xf4  ? 4
                  : c >= 0xe0 && c < 0xf0 ? 3
                  : c >= 0xc2 && c < 0xe0 ? 2
                                          : 0;
  if (n == 0 || s.size() < n) return 0;
  for (std::size_t i = 1; i < n; ++i)
    if ((static_cast<unsigned char>(s[i]) & 0xc0) != 0x80) return 0;
  // no overlong forms, no surrogates, nothing beyond U+10FFFF (RFC 3629)
  auto second = static_cast<unsigned char>(s[1]);
  if ((c == 0xe0 && second < 0xa0) || (c == 0xed && second > 0x9f) ||
      (c == 0xf0 && second < 0x90) || (c == 0xf4 && second > 0x8f))
    return 0;
  return n;
}

std::string printable(std::string_view text, std::size_t maxBytes) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    auto c = static_cast<unsigned char>(text[i]);
    std::string piece;
    std::size_t n = 1;
    if (c >= 0x20 && c < 0x7f) {
      piece = static_cast<char>(c);
    } else if (n = c >= 0x80 ? utf8Length(text.substr(i)) : 0; n > 0) {
      piece = text.substr(i, n);
    } else {
      n = 1;
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      piece = hex;
    }
    if (out.size() + piece.size() > maxBytes) break;
    out += piece;
    i += n;
  }
  if (i < text.size()) out += "…";
  return out;
}

std::string markupEscaped(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace pitwall
