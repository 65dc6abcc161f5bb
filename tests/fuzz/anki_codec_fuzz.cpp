// The Anki codec (engine/protocol/anki/codec.hpp) and the JSON of its messages: any bytes decode
// to a message or a DecodeError (never a crash, an out-of-bounds read or an exception), and a
// decoded message survives the round trip:
// - encode(decode(bytes)) has the input's id, and equals the input except in the canonical form
//   documented by message_fields.hpp: a bool byte other than 0 is written as 01, bytes no field
//   carries are written as 00, and a message whose longer layout adds no field (the version
//   response's 4-byte form) is written in its shorter layout, and a lane-change update read in
//   its 15-byte form is written in the documented 16-byte one (a zero byte more);
// - that canonical frame is a fixed point: decode → encode gives it back byte for byte, and both
//   decodes give the same JSON (compared as JSON so that a NaN offset compares equal to itself).
#include <cstddef>
#include <cstdint>
#include <span>

#include "engine/protocol/anki/codec.hpp"
#include "engine/protocol/anki/message_json.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  auto decoded = anki::decode(in);
  if (!decoded) {
    FUZZ_CHECK(!decoded.error().message().empty());
    return 0;
  }
  const anki::Message& m = *decoded;
  FUZZ_CHECK(!anki::name(m).empty());
  const std::string json = anki::toJson(m).dump();

  const anki::Frame f = anki::encode(m);
  const auto out = f.span();
  const std::string both = fuzz::bytesText("in", in) + "; " + fuzz::bytesText("out", out);
  const bool longerForm =
      in[1] == anki::id::kLaneChangeUpdate && in.size() == 15 && out.size() == 16;
  FUZZ_CHECK(
      out.size() == in.size() || longerForm || (out.size() < in.size() && out[0] == out.size() - 1),
      both);
  FUZZ_CHECK(out[1] == in[1] && anki::messageId(m) == in[1], both);
  for (std::size_t i = 1; i < out.size(); ++i) {
    const bool canonical =
        i >= in.size() ? out[i] == 0 : out[i] == in[i] || out[i] == 0 || (out[i] == 1 && in[i] > 1);
    FUZZ_CHECK(canonical, both);
  }

  auto again = anki::decode(out);
  FUZZ_CHECK(again.ok(), fuzz::bytesText("re-encoded", out) + ": " +
                             (again ? std::string() : again.error().message()));
  FUZZ_CHECK(anki::encode(*again) == f, fuzz::bytesText("in", in));
  FUZZ_CHECK(anki::toJson(*again).dump() == json, json + " vs " + anki::toJson(*again).dump());
  return 0;
}
