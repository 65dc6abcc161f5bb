// What an Anki car advertises (engine/protocol/anki/advertisement.hpp): the manufacturer data in
// both shapes (8 raw bytes; BlueZ's key + value) and the local name. Never a crash or an exception;
// parseLocalName never fails and gives valid UTF-8 (documented), and the two manufacturer-data
// shapes agree: raw bytes [BE EF rest…] parse exactly as key 0xEFBE with value [rest…]; a name
// that localNameText takes comes back from its text form unchanged.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/protocol/anki/advertisement.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  auto raw = anki::parseManufacturerData(in);
  if (raw) {
    FUZZ_CHECK(in.size() >= 2, fuzz::bytesText("in", in));
    (void)anki::modelName(raw->model_id);
    (void)anki::uniqueCarName(raw->model_id, {anki::modelName(raw->model_id)});
  } else {
    FUZZ_CHECK(!raw.error().empty());
  }
  // BlueZ's shape: the first two bytes as the little-endian company key, the rest as the value.
  if (in.size() >= 2) {
    const int key = in[0] | in[1] << 8;
    auto split = anki::parseManufacturerData(key, in.subspan(2));
    FUZZ_CHECK(split.ok() || !split.error().empty());
    if (key == anki::kManufacturerKey) {
      FUZZ_CHECK(split.ok() == raw.ok(), fuzz::bytesText("in", in));
      if (split && raw) {
        FUZZ_CHECK(split->model_id == raw->model_id && split->identifier == raw->identifier &&
                       split->product_id == raw->product_id,
                   fuzz::bytesText("in", in));
      }
    }
    (void)anki::parseManufacturerData(key - 0x10000, in.subspan(2));  // the signed form
  }
  const anki::LocalName name = anki::parseLocalName(in);
  // Each byte that is not UTF-8 becomes U+FFFD (3 bytes), so the name is valid UTF-8: JSON takes
  // it (dump() throws on invalid UTF-8, which this would report as a crash).
  FUZZ_CHECK(name.user_name.size() <= 3 * in.size(), fuzz::bytesText("in", in));
  (void)nlohmann::json(name.user_name).dump();
  // The text form (emulate-car's LocalName) holds no NUL and reads back as what it was made of.
  if (auto text = anki::localNameText(name)) {
    const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(text->data()),
                                              text->size());
    FUZZ_CHECK(text->find('\0') == std::string::npos && anki::isAnkiLocalName(bytes),
               fuzz::bytesText("in", in));
    const anki::LocalName back = anki::parseLocalName(bytes);
    FUZZ_CHECK(back.full_battery == name.full_battery && back.low_battery == name.low_battery &&
                   back.on_charger == name.on_charger && back.version == name.version &&
                   back.user_name == name.user_name,
               fuzz::bytesText("in", in));
  } else {
    FUZZ_CHECK(!text.error().empty());
  }
  return 0;
}
