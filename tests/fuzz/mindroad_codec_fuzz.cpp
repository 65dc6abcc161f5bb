// The MindRoad codec (engine/protocol/mindroad/codec.hpp): any bytes decode to an instruction or
// a DecodeError, never a crash or an exception. A decoded instruction passes validate() (decode
// checks the same ranges) and encodes back to exactly the input bytes: the header's length nibble
// and every data byte are carried, so the wire form has no other canonical form. The contact
// answer decoder is total too, and its JSON and the errors' sentences are built for every input.
#include <cstddef>
#include <cstdint>
#include <span>

#include "engine/protocol/mindroad/codec.hpp"
#include "engine/protocol/mindroad/message_json.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);

  auto answer = mindroad::decodeAnswer(in);
  FUZZ_CHECK(answer.ok() == (size == 1 && data[0] == mindroad::kContactAnswer),
             fuzz::bytesText("in", in));
  if (!answer) FUZZ_CHECK(!answer.error().message().empty());

  auto decoded = mindroad::decode(in);
  if (!decoded) {
    FUZZ_CHECK(!decoded.error().message().empty());
    return 0;
  }
  const mindroad::Instruction& m = *decoded;
  FUZZ_CHECK(!mindroad::validate(m), fuzz::bytesText("in", in) + ": " + *mindroad::validate(m));
  FUZZ_CHECK(mindroad::instructionId(m) == data[0] >> 4, fuzz::bytesText("in", in));
  (void)mindroad::toJson(m).dump();

  const mindroad::Frame f = mindroad::encode(m);
  FUZZ_CHECK(std::ranges::equal(f.span(), in),
             fuzz::bytesText("in", in) + "; " + fuzz::bytesText("out", f.span()));
  return 0;
}
