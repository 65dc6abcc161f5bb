#pragma once
// bytes ⇄ instructions for the MindRoad robot car. Pure: no I/O. Decoding is total: every byte
// string gives an Instruction or a DecodeError naming the id and the lengths.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/protocol/mindroad/messages.hpp"

namespace pitwall::mindroad {

struct DecodeError {
  enum class Kind {
    Empty,           // no bytes at all
    UnusedId,        // ids 8–15: the robot stops (seed 002 table 1)
    LengthMismatch,  // the header's length nibble disagrees with the bytes received
    WrongLength,     // the header announces a data length this id does not have
    OutOfRange,      // a data value outside the range the seed gives (click, picture mode)
    NotAnAnswer,     // robot → client: a byte other than K
  };
  Kind kind = Kind::Empty;
  std::uint8_t id = 0;          // instruction id (high nibble of the header)
  std::size_t expected = 0;     // data bytes expected (WrongLength, LengthMismatch)
  std::size_t received = 0;     // data bytes announced (WrongLength) or received (LengthMismatch)
  std::string field;            // OutOfRange: which value
  int value = 0;                // OutOfRange: the value; NotAnAnswer: the byte
  std::string message() const;  // one sentence naming the id and the lengths
};

// Data bytes each used id carries (seed 002 table 1); nullopt for 8–15.
std::optional<std::size_t> dataLength(std::uint8_t id);

// Client → robot: exactly one instruction, header and data.
Result<Instruction, DecodeError> decode(std::span<const std::uint8_t> bytes);
Frame encode(const Instruction& instruction);

// Robot → client: the contact answer. Result<bool> is true for K.
Result<bool, DecodeError> decodeAnswer(std::span<const std::uint8_t> bytes);
// Robot → client bytes cut into answers: every answer is one byte (mindroad.md "Behaviour"), so
// the next frame of `pending` is its first byte (0 when there is none).
inline std::size_t answerLength(std::span<const std::uint8_t> pending) {
  return pending.empty() ? 0 : 1;
}

// Stable kebab-case name: "stop", "contact", "steering", "mouse-position", "buttons", "ping",
// "picture-mode", "shutdown".
std::string_view name(const Instruction& instruction);
std::uint8_t instructionId(const Instruction& instruction);

// An instruction built by a caller (CLI, Lua, client) that is out of the seed's ranges; nullopt
// when it is valid. Steering and buttons are valid for every byte.
std::optional<std::string> validate(const Instruction& instruction);

// Splits a byte stream (TCP) into instructions by their headers: an instruction may arrive in
// pieces or several in one read. An unused id or a wrong length is still framed by its length
// nibble, so one bad instruction costs only itself.
class StreamDecoder {
 public:
  // Appends bytes; returns every instruction (or error) completed by them, in order.
  std::vector<Result<Instruction, DecodeError>> feed(std::span<const std::uint8_t> bytes);
  // Bytes of an instruction begun but not complete.
  std::size_t pending() const { return buffer_.size(); }

 private:
  std::vector<std::uint8_t> buffer_;
};

}  // namespace pitwall::mindroad
