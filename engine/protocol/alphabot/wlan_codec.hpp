#pragma once
// bytes ⇄ messages for the Alphabot's WLAN packet protocol (../shared/protocols/alphabot.md §1).
// A packet is one id byte and its fields; every packet's length follows from its id (for 0x83
// from its count byte too), so a TCP stream needs no framing. Pure: no I/O.
//
// Decisions the reference leaves open, made here:
// - byte order: little-endian by default (as the BLE side and the Anki cars); an option.
//   The toggle field is two single bytes (settings, then logging) in either order.
// - 0xC0 (the source's "1100 0000" for toggles) decodes as 0x05; we always encode 0x05.
// - 0x83 path: u8 count, then count × (i16 x, i16 y).
// Decoding is total: a message, or a DecodeError naming the id and the lengths.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/protocol/alphabot/messages.hpp"

namespace pitwall::alphabot::wlan {

enum class ByteOrder { Little, Big };
struct Options {
  ByteOrder order = ByteOrder::Little;
};

using Packet = std::variant<Request, Response>;
using Bytes = std::vector<std::uint8_t>;

struct DecodeError {
  enum class Kind {
    Empty,           // no bytes at all
    UnknownId,       // an id no packet has (the stream decoder skipped `received` bytes)
    WrongDirection,  // a request where responses are expected, or the other way round
    TooShort,        // fewer bytes than the id's layout needs
    TooLong,         // more bytes than the id's layout has
  };
  Kind kind = Kind::Empty;
  std::uint8_t id = 0;
  std::size_t expected = 0;  // packet length in bytes, id included, where it applies
  std::size_t received = 0;  // bytes received (for UnknownId: bytes skipped)
  std::string message() const;
};

constexpr std::uint8_t kToggleAlias = 0xC0;  // decodes as 0x05 (alphabot.md §1)

// Requests are always encodable. Responses are too, except the BLE-only ones (map size, anchor
// position, calibration finished) and a path of more than 255 waypoints: an error then.
Bytes encode(const Request& request, Options options = {});
Result<Bytes, std::string> encode(const Response& response, Options options = {});

// Exactly one packet: trailing bytes are an error (TooLong).
Result<Packet, DecodeError> decode(std::span<const std::uint8_t> bytes, Options options = {});

// The id a message travels with, and its name as `pitwall decode`/`encode` spell it
// ("drive", "distance", …; "map-size" etc. for the BLE-only responses).
std::uint8_t packetId(const Request& request);
std::uint8_t packetId(const Response& response);
std::string_view name(const Request& request);
std::string_view name(const Response& response);
std::string_view nameOfId(std::uint8_t id);  // "" for an unknown id
bool isRequestId(std::uint8_t id);           // 0x01..0x0C, 0xC0
bool isResponseId(std::uint8_t id);          // 0x81..0x86

// Where a stream of `accept`ed packets cuts: the length of the next frame at the start of
// `pending` (bytes received, not yet framed), 0 when its packet is not complete yet. A run of
// bytes that is not an accepted packet (up to the next byte that is an accepted id, or all of
// `pending`) is a frame of its own, for decodeFrom to report (the resynchronisation below).
enum class Accept { Requests, Responses, Both };
std::size_t frameLength(std::span<const std::uint8_t> pending, Accept accept);

// Decodes one frame cut by frameLength: a packet, or the error the stream decoder reports for
// it (UnknownId or WrongDirection with received = the frame's length).
Result<Packet, DecodeError> decodeFrame(std::span<const std::uint8_t> frame, Accept accept,
                                        Options options = {});

// Reassembles packets from a TCP stream: bytes may arrive split or merged in any way.
// Resynchronisation: a byte at the start of a packet that is not an accepted id is skipped,
// together with every following byte up to the next byte that is an accepted id, and reported
// as one UnknownId/WrongDirection error (received = bytes skipped). A known id is trusted: its
// packet is taken whole (a corrupted length cannot be detected without framing).
class StreamDecoder {
 public:
  using Accept = wlan::Accept;
  explicit StreamDecoder(Accept accept, Options options = {})
      : accept_(accept), options_(options) {}
  void feed(std::span<const std::uint8_t> bytes);
  // The next packet or error; nullopt when more bytes are needed.
  std::optional<Result<Packet, DecodeError>> next();
  std::size_t buffered() const { return buffer_.size() - start_; }
  void reset() {
    buffer_.clear();
    start_ = 0;
  }

 private:
  Accept accept_;
  Options options_;
  Bytes buffer_;
  std::size_t start_ = 0;
};

}  // namespace pitwall::alphabot::wlan
