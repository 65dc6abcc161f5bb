#pragma once
// bytes ⇄ messages for the Anki Overdrive protocol. Pure: no I/O, no allocation on the hot path.
// Decoding is total: every byte string gives a Message (possibly Unknown) or a DecodeError.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "engine/core/result.hpp"
#include "engine/protocol/anki/messages.hpp"

namespace pitwall::anki {

struct DecodeError {
  enum class Kind {
    Empty,         // no bytes at all
    SizeMismatch,  // size byte disagrees with the number of bytes received
    TooShort,      // fewer payload bytes than the message's layout needs
    TooLong,       // more payload bytes than any known layout of that id
    TooBig,        // more than 20 bytes
  };
  Kind kind = Kind::Empty;
  std::uint8_t id = 0;          // message id when known (0 for Empty)
  std::size_t expected = 0;     // bytes expected (frame length), where it applies
  std::size_t received = 0;     // bytes received (frame length)
  std::string message() const;  // one sentence naming the id and the lengths
};

Result<Message, DecodeError> decode(std::span<const std::uint8_t> bytes);
Frame encode(const Message& message);

// Stable kebab-case name: "set-speed", "position-update", "unknown", …
std::string_view name(const Message& message);
std::uint8_t messageId(const Message& message);

}  // namespace pitwall::anki
