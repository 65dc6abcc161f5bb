// The Alphabot WLAN codec (engine/protocol/alphabot/wlan_codec.hpp), in both byte orders: any
// bytes decode to a packet or a DecodeError, never a crash or an exception. A decoded packet
// encodes back to exactly the input bytes, except the documented alias: a toggles request sent
// as 0xC0 is encoded as 0x05. A decoded response is always encodable (it came over WLAN). The
// JSON of every decoded message and the sentence of every error are built too.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <variant>
#include <vector>

#include "engine/protocol/alphabot/message_json.hpp"
#include "engine/protocol/alphabot/wlan_codec.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;
using namespace pitwall::alphabot;

namespace {

void roundTrip(std::span<const std::uint8_t> in, wlan::Options options) {
  auto decoded = wlan::decode(in, options);
  if (!decoded) {
    FUZZ_CHECK(!decoded.error().message().empty());
    return;
  }
  wlan::Bytes out;
  if (const auto* request = std::get_if<Request>(&*decoded)) {
    (void)toJson(*request).dump();
    out = wlan::encode(*request, options);
  } else {
    const auto& response = std::get<Response>(*decoded);
    (void)toJson(response).dump();
    auto encoded = wlan::encode(response, options);
    FUZZ_CHECK(encoded.ok(), fuzz::bytesText("in", in) + ": " + encoded.error());
    out = std::move(*encoded);
  }
  std::vector<std::uint8_t> canonical(in.begin(), in.end());
  if (canonical[0] == wlan::kToggleAlias) canonical[0] = 0x05;
  FUZZ_CHECK(out == canonical, fuzz::bytesText("in", in) + "; " + fuzz::bytesText("out", out));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  roundTrip(in, {wlan::ByteOrder::Little});
  roundTrip(in, {wlan::ByteOrder::Big});
  return 0;
}
