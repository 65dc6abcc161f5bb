// The Alphabot BLE codec (engine/protocol/alphabot/ble_codec.hpp). The first input byte picks the
// characteristic, the rest is the value written, notified or read. Any value decodes, in both
// directions, to a message or a BleCodecError naming the characteristic — never a crash or an
// exception — and `pitwall decode alphabot-ble`'s decodeBle() gives JSON or an error sentence.
// A decoded message is always encodable (it came over BLE), travels on the same characteristic,
// and decodes back to the same message. The encoding is the canonical value: bytes the message
// does not carry (padding, the low nibble of a SENSOR query) are zero, so the check is on the
// message, plus the encoding being a fixed point (encode ∘ decode gives it back byte for byte).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <variant>

#include "engine/core/overload.hpp"
#include "engine/protocol/alphabot/ble_codec.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;
using namespace pitwall::alphabot;
using namespace pitwall::alphabot::ble;

namespace {

std::string context(Characteristic c, std::span<const std::uint8_t> value) {
  return std::string(info(c).name) + " " + fuzz::bytesText("value", value);
}

// What a client writes.
void request(Characteristic c, std::span<const std::uint8_t> value) {
  auto decoded = decodeRequest(c, value);
  if (!decoded) {
    FUZZ_CHECK(decoded.error().characteristic == c && !decoded.error().message.empty());
    return;
  }
  auto encoded = std::visit([](const auto& m) { return encode(m); }, *decoded);
  FUZZ_CHECK(encoded.ok(), context(c, value) + ": " + encoded.error().message);
  FUZZ_CHECK(encoded->characteristic == c, context(c, value));
  auto again = decodeRequest(c, encoded->bytes);
  FUZZ_CHECK(again.ok() && *again == *decoded,
             context(c, value) + "; " + fuzz::bytesText("encoded", encoded->bytes));
  auto twice = std::visit([](const auto& m) { return encode(m); }, *again);
  FUZZ_CHECK(twice.ok() && *twice == *encoded, context(c, value));
}

// What a robot notifies or serves.
void response(Characteristic c, std::span<const std::uint8_t> value) {
  auto decoded = decodeResponse(c, value);
  if (!decoded) {
    FUZZ_CHECK(decoded.error().characteristic == c && !decoded.error().message.empty());
    return;
  }
  auto encoded =
      std::visit(Overload{[](const Response& r) { return encode(r); },
                          [](const auto& m) { return Result<BleValue, BleCodecError>(encode(m)); }},
                 *decoded);
  FUZZ_CHECK(encoded.ok(), context(c, value) + ": " + encoded.error().message);
  FUZZ_CHECK(encoded->characteristic == c, context(c, value));
  auto again = decodeResponse(c, encoded->bytes);
  FUZZ_CHECK(again.ok() && *again == *decoded,
             context(c, value) + "; " + fuzz::bytesText("encoded", encoded->bytes));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const auto c = static_cast<Characteristic>(data[0] % characteristics().size());
  const std::span<const std::uint8_t> value(data + 1, size - 1);
  request(c, value);
  response(c, value);
  auto json = decodeBle(info(c).name, value);
  if (json) {
    (void)json->dump();
  } else {
    FUZZ_CHECK(!json.error().empty());
  }
  // The name lookup the command line uses, on arbitrary text.
  const std::string text(reinterpret_cast<const char*>(data), size);
  if (auto named = characteristicNamed(text)) FUZZ_CHECK(characteristicNamed(info(*named).uuid));
  return 0;
}
