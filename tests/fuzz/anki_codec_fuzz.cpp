// The Anki codec (engine/protocol/anki/codec.hpp) and the JSON of its messages: any bytes decode
// to a message or a DecodeError (never a crash, an out-of-bounds read or an exception), and a
// decoded message survives the round trip:
// - a frame longer than the longest layout of its id reads as the frame cut to that layout (size
//   byte to match), and the bytes cut off are extraBytes(bytes) (anki-overdrive.md **Decision**);
// - encode(decode(bytes)) has the input's id, and equals the input without its extra bytes
//   except in the canonical form documented by message_fields.hpp: a bool byte other than 0 is
//   written as 01, bytes no field carries are written as 00, a message whose longer layout adds
//   no field (the version response's 4-byte form) is written in its shorter layout, and a
//   lane-change update read in its 15-byte form is written in the documented 16-byte one (a zero
//   byte more);
// - that canonical frame is a fixed point: decode → encode gives it back byte for byte, and both
//   decodes give the same JSON (compared as JSON so that a NaN offset compares equal to itself);
// - decodeCommand (the vehicle side) reads what decode() reads, the same, and besides only the
//   short set speed `05 24 <speed> <accel>`, as the set speed with a zero byte appended.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <variant>
#include <vector>

#include "engine/protocol/anki/codec.hpp"
#include "engine/protocol/anki/message_json.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  auto decoded = anki::decode(in);
  auto command = anki::decodeCommand(in);
  if (decoded) {
    FUZZ_CHECK(command.ok() && anki::encode(*command) == anki::encode(*decoded),
               fuzz::bytesText("in", in));
  } else if (command) {
    FUZZ_CHECK(in.size() == 6 && in[0] == 5 && in[1] == anki::id::kSetSpeed &&
                   std::holds_alternative<anki::SetSpeed>(*command),
               fuzz::bytesText("in", in));
    std::vector<std::uint8_t> whole(in.begin(), in.end());
    whole[0] = 6;
    whole.push_back(0);
    FUZZ_CHECK(anki::encode(*command).span().size() == 7 &&
                   std::equal(whole.begin(), whole.end(), anki::encode(*command).bytes.begin()),
               fuzz::bytesText("in", in));
  }
  if (!decoded) {
    FUZZ_CHECK(!decoded.error().message().empty());
    return 0;
  }
  const anki::Message& m = *decoded;
  FUZZ_CHECK(!anki::name(m).empty());
  const std::string json = anki::toJson(m).dump();

  // Extra bytes are the input's tail past a layout; without them the input reads the same.
  const auto extra = anki::extraBytes(in);
  FUZZ_CHECK(extra.empty() || (extra.data() + extra.size() == in.data() + in.size() &&
                               extra.size() < in.size() - 1),
             fuzz::bytesText("in", in));
  const auto whole = in.first(in.size() - extra.size());
  if (!extra.empty()) {
    anki::Frame cut;
    std::copy(whole.begin(), whole.end(), cut.bytes.begin());
    cut.bytes[0] = static_cast<std::uint8_t>(whole.size() - 1);
    cut.length = static_cast<std::uint8_t>(whole.size());
    auto plain = anki::decode(cut.span());
    FUZZ_CHECK(
        plain.ok() && anki::encode(*plain) == anki::encode(m) &&
            anki::extraBytes(cut.span()).empty(),
        fuzz::bytesText("in", in) + " does not read as " + fuzz::bytesText("cut", cut.span()));
  }

  const anki::Frame f = anki::encode(m);
  const auto out = f.span();
  const std::string both = fuzz::bytesText("in", in) + "; " + fuzz::bytesText("out", out);
  const bool longerForm =
      in[1] == anki::id::kLaneChangeUpdate && whole.size() == 15 && out.size() == 16;
  FUZZ_CHECK(out.size() == whole.size() || longerForm ||
                 (out.size() < whole.size() && out[0] == out.size() - 1),
             both);
  FUZZ_CHECK(out[1] == in[1] && anki::messageId(m) == in[1], both);
  for (std::size_t i = 1; i < out.size(); ++i) {
    const bool canonical = i >= whole.size()
                               ? out[i] == 0
                               : out[i] == whole[i] || out[i] == 0 || (out[i] == 1 && whole[i] > 1);
    FUZZ_CHECK(canonical, both);
  }

  auto again = anki::decode(out);
  FUZZ_CHECK(again.ok(), fuzz::bytesText("re-encoded", out) + ": " +
                             (again ? std::string() : again.error().message()));
  FUZZ_CHECK(anki::encode(*again) == f, fuzz::bytesText("in", in));
  FUZZ_CHECK(anki::toJson(*again).dump() == json, json + " vs " + anki::toJson(*again).dump());
  return 0;
}
