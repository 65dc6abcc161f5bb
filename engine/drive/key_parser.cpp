#include "engine/drive/key_parser.hpp"

#include <optional>

namespace pitwall::drive {

namespace {
constexpr char kEsc = 0x1b;
// A CSI sequence longer than this is no key a terminal sends: it is dropped, and parsing starts
// over, so random bytes cannot keep the parser in a sequence for ever.
constexpr std::size_t kMaxSequence = 16;

std::optional<Key> arrow(char final) {
  switch (final) {
    case 'A':
      return Key::Up;
    case 'B':
      return Key::Down;
    case 'C':
      return Key::Right;
    case 'D':
      return Key::Left;
    default:
      return std::nullopt;
  }
}
}  // namespace

std::vector<Key> KeyParser::feed(std::string_view bytes) {
  std::vector<Key> keys;
  for (char c : bytes) {
    const auto u = static_cast<unsigned char>(c);
    switch (state_) {
      case State::Ground:
        if (c == kEsc)
          state_ = State::Escape;
        else if (c == ' ')
          keys.push_back(Key::Space);
        break;
      case State::Escape:
        if (c == '[') {
          state_ = State::Csi;
          length_ = 0;
        } else if (c == 'O') {
          state_ = State::Ss3;
        } else if (c != kEsc) {    // ESC ESC: the first was a lone Esc key
          state_ = State::Ground;  // Alt+key, or a lone Esc then a key: not ours
          if (c == ' ') keys.push_back(Key::Space);
        }
        break;
      case State::Csi:
        // ECMA-48 §5.4: parameter bytes 0x30–0x3F, intermediate bytes 0x20–0x2F, then one
        // final byte 0x40–0x7E. Anything else cancels the sequence.
        if (u >= 0x40 && u <= 0x7e) {
          if (auto k = arrow(c)) keys.push_back(*k);
          state_ = State::Ground;
        } else if (u >= 0x20 && u <= 0x3f && ++length_ <= kMaxSequence) {
          // still inside
        } else {
          state_ = c == kEsc ? State::Escape : State::Ground;
        }
        break;
      case State::Ss3:
        if (auto k = arrow(c)) keys.push_back(*k);
        state_ = c == kEsc ? State::Escape : State::Ground;
        break;
    }
  }
  return keys;
}

}  // namespace pitwall::drive
