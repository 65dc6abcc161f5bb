// The MindRoad stream decoder (mindroad::StreamDecoder, which the simulated robot's TCP server
// uses to split a byte stream into instructions). The first input byte picks where the rest is
// cut into reads; whatever the cuts, the decoder gives the same results as one read of the whole
// stream, each one what decode() says about that instruction's bytes, and keeps only the bytes of
// one unfinished instruction (header + at most 15 data bytes) pending.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/protocol/mindroad/codec.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;

namespace {

using Results = std::vector<pitwall::Result<mindroad::Instruction, mindroad::DecodeError>>;

bool same(const Results& a, const Results& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].ok() != b[i].ok()) return false;
    if (a[i].ok() ? !(*a[i] == *b[i]) : a[i].error().message() != b[i].error().message())
      return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t cuts = data[0];
  const std::span<const std::uint8_t> stream(data + 1, size - 1);

  mindroad::StreamDecoder whole;
  const Results expected = whole.feed(stream);

  // Reads of 1..7 bytes, their sizes taken from the bits of `cuts` in turn; where the bits are
  // 0, an empty read and then one byte.
  mindroad::StreamDecoder pieces;
  Results got;
  std::size_t at = 0;
  for (unsigned step = 0; at < stream.size(); ++step) {
    std::size_t n = (cuts >> (step % 6)) & 7;
    if (n == 0) {
      FUZZ_CHECK(pieces.feed({}).empty());
      n = 1;
    }
    n = std::min(n, stream.size() - at);
    for (auto& r : pieces.feed(stream.subspan(at, n))) got.push_back(std::move(r));
    FUZZ_CHECK(pieces.pending() <= 16, fuzz::bytesText("stream", stream));
    at += n;
  }
  FUZZ_CHECK(same(expected, got), fuzz::bytesText("stream", stream));
  FUZZ_CHECK(whole.pending() == pieces.pending(), fuzz::bytesText("stream", stream));

  // Each result is decode() of the bytes its header frames.
  std::size_t offset = 0;
  for (const auto& r : expected) {
    const std::size_t length = 1 + (stream[offset] & 0x0f);
    Results one;
    one.push_back(mindroad::decode(stream.subspan(offset, length)));
    FUZZ_CHECK(same(one, Results{r}), fuzz::bytesText("stream", stream));
    offset += length;
  }
  FUZZ_CHECK(offset + whole.pending() == stream.size(), fuzz::bytesText("stream", stream));
  return 0;
}
