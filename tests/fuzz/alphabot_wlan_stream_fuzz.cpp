// The Alphabot WLAN stream decoder (wlan::StreamDecoder, used by the TCP link and the simulated
// robot's server). The first input byte picks what the decoder accepts (requests, responses or
// both), the byte order and where the rest is cut into reads. Whatever the cuts:
// - the packets are the same, in the same order, as from one read of the whole stream;
// - the bytes skipped as unknown or wrong-direction add up to the same count (a run of such
//   bytes cut by a read may be reported in two errors);
// - the bytes still buffered at the end are the same;
// - each packet is what decode() makes of its bytes, and it travels in an accepted direction.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <variant>
#include <vector>

#include "engine/protocol/alphabot/wlan_codec.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;
using namespace pitwall::alphabot;

namespace {

struct Outcome {
  std::vector<wlan::Packet> packets;
  std::size_t skipped = 0;
};

void drain(wlan::StreamDecoder& decoder, Outcome& out) {
  while (auto next = decoder.next()) {
    if (next->ok()) {
      out.packets.push_back(std::move(next->value()));
    } else {
      const auto& e = next->error();
      FUZZ_CHECK(e.kind == wlan::DecodeError::Kind::UnknownId ||
                 e.kind == wlan::DecodeError::Kind::WrongDirection);
      FUZZ_CHECK(e.received > 0 && !e.message().empty());
      out.skipped += e.received;
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t control = data[0];
  const std::span<const std::uint8_t> stream(data + 1, size - 1);
  using Accept = wlan::StreamDecoder::Accept;
  const Accept accept = control % 3 == 0   ? Accept::Requests
                        : control % 3 == 1 ? Accept::Responses
                                           : Accept::Both;
  const wlan::Options options{control & 0x80 ? wlan::ByteOrder::Big : wlan::ByteOrder::Little};

  wlan::StreamDecoder whole(accept, options);
  Outcome expected;
  whole.feed(stream);
  drain(whole, expected);

  // Reads of 1..8 bytes, sizes from bits 2–6 of the control byte in turn.
  wlan::StreamDecoder pieces(accept, options);
  Outcome got;
  std::size_t at = 0;
  for (unsigned step = 0; at < stream.size(); ++step) {
    const std::size_t n =
        std::min<std::size_t>(1 + ((control >> (2 + step % 3)) & 7), stream.size() - at);
    pieces.feed(stream.subspan(at, n));
    drain(pieces, got);
    at += n;
  }
  FUZZ_CHECK(got.packets == expected.packets, fuzz::bytesText("stream", stream));
  FUZZ_CHECK(got.skipped == expected.skipped, fuzz::bytesText("stream", stream));
  FUZZ_CHECK(got.skipped + whole.buffered() <= stream.size());
  FUZZ_CHECK(pieces.buffered() == whole.buffered(), fuzz::bytesText("stream", stream));

  // Each packet is decode() of its own bytes, which its encoding gives back.
  for (const auto& packet : expected.packets) {
    const bool request = std::holds_alternative<Request>(packet);
    FUZZ_CHECK(accept == Accept::Both || (accept == Accept::Requests) == request);
    wlan::Bytes bytes;
    if (request) {
      bytes = wlan::encode(std::get<Request>(packet), options);
    } else {
      auto encoded = wlan::encode(std::get<Response>(packet), options);
      FUZZ_CHECK(encoded.ok());
      bytes = std::move(*encoded);
    }
    auto decoded = wlan::decode(bytes, options);
    FUZZ_CHECK(decoded.ok() && *decoded == packet, fuzz::bytesText("packet", bytes));
  }
  return 0;
}
