#pragma once
// bytes ⇄ messages for the Anki Overdrive protocol. Pure: no I/O, no allocation on the hot path.
// Decoding is total: every byte string gives a Message (possibly Unknown) or a DecodeError. A
// frame longer than its layout is no error: it is read by its longest layout and the bytes past
// it are left to extraBytes() (anki-overdrive.md **Decision**).
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

// The bytes of a frame past the longest layout of its id: what decode() read the frame without.
// Empty when the frame fits its layout, for an unknown id (kept whole in Unknown::raw) and for a
// frame decode() refuses. A firmware that appends a field to a message sends these.
std::span<const std::uint8_t> extraBytes(std::span<const std::uint8_t> frame);
// The same, inline for the frame cars send most (a position update of exactly its layout, the
// size codec.cpp checks against the layout): every received frame asks.
inline constexpr std::size_t kPositionUpdateFrameSize = 17;
inline std::span<const std::uint8_t> extraBytesOfReceived(std::span<const std::uint8_t> frame) {
  if (frame.size() == kPositionUpdateFrameSize && frame[1] == id::kPositionUpdate) return {};
  return extraBytes(frame);
}

// What a car makes of a frame written to it (the vehicle side: simulated and emulated cars):
// decode(), and also the short command forms real firmware accepts, read with the missing
// trailing fields at their defaults (anki-overdrive.md **Decision**): set speed without its last
// byte, `05 24 <speed i16> <accel i16>` (sent by py-drivesdk), is set speed with respect-limit 0.
Result<Message, DecodeError> decodeCommand(std::span<const std::uint8_t> bytes);

// Stable kebab-case name: "set-speed", "position-update", "unknown", …
std::string_view name(const Message& message);
std::uint8_t messageId(const Message& message);

}  // namespace pitwall::anki
