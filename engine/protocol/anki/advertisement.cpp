// What an Anki car advertises (anki-overdrive.md "Advertisement"; seed 000 §4.3.1).
#include "engine/protocol/anki/advertisement.hpp"

#include <cctype>

#include <algorithm>

#include <array>
#include <cstdio>

namespace pitwall::anki {
namespace {

constexpr std::uint16_t kProductId = 0xBEEF;
constexpr int kManufacturerKeySigned = -4162;  // 0xEFBE read as int16 by some stacks
constexpr std::size_t kRawSize = 8;            // [BE EF][reserved][model][id ×4]
constexpr std::size_t kValueSize = 6;          // the same without the two key bytes

std::string hex16(unsigned v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%04X", v & 0xffffu);
  return buf;
}

// [reserved][model][identifier, 4 bytes big-endian] — the part after the product id.
ManufacturerData fromValue(std::span<const std::uint8_t> v) {
  ManufacturerData d;
  d.model_id = v[1];
  d.identifier = (std::uint32_t{v[2]} << 24) | (std::uint32_t{v[3]} << 16) |
                 (std::uint32_t{v[4]} << 8) | std::uint32_t{v[5]};
  return d;
}

// Length of the UTF-8 sequence starting at s[i] if it is well formed, else 0.
std::size_t utf8Sequence(std::span<const std::uint8_t> s, std::size_t i) {
  const std::uint8_t b = s[i];
  if (b < 0x80) return 1;
  std::size_t n = 0;
  std::uint32_t cp = 0;
  if ((b & 0xE0) == 0xC0) {
    n = 2, cp = b & 0x1F;
  } else if ((b & 0xF0) == 0xE0) {
    n = 3, cp = b & 0x0F;
  } else if ((b & 0xF8) == 0xF0) {
    n = 4, cp = b & 0x07;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((s[i + k] & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (s[i + k] & 0x3F);
  }
  static constexpr std::array<std::uint32_t, 5> kMin{0, 0, 0x80, 0x800, 0x10000};
  if (cp < kMin[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

// The user name is meant to be UTF-8; a cut-short or garbled one keeps its readable part and
// shows U+FFFD for each bad byte, so it can always be printed and put into JSON.
std::string utf8OrReplacement(std::span<const std::uint8_t> s) {
  std::string out;
  for (std::size_t i = 0; i < s.size();) {
    if (const std::size_t n = utf8Sequence(s, i)) {
      out.append(reinterpret_cast<const char*>(s.data() + i), n);
      i += n;
    } else {
      out += "\xEF\xBF\xBD";
      ++i;
    }
  }
  return out;
}

}  // namespace

Result<ManufacturerData, std::string> parseManufacturerData(std::span<const std::uint8_t> raw) {
  if (raw.size() < kRawSize) {
    return Unexpected{"manufacturer data has " + std::to_string(raw.size()) +
                      " bytes, an Anki car sends " + std::to_string(kRawSize)};
  }
  // anki-overdrive.md: product id big-endian, bytes BE EF.
  const unsigned product = (unsigned{raw[0]} << 8) | raw[1];
  if (product != kProductId) {
    return Unexpected{"manufacturer data starts with product id " + hex16(product) + ", not " +
                      hex16(kProductId) + ": not an Anki car"};
  }
  return fromValue(raw.subspan(2));
}

Result<ManufacturerData, std::string> parseManufacturerData(int key,
                                                            std::span<const std::uint8_t> value) {
  if (key != kManufacturerKey && key != kManufacturerKeySigned) {
    return Unexpected{"manufacturer data key " + std::to_string(key) + " (" + hex16(key) +
                      ") is not Anki's " + hex16(kManufacturerKey) + " (" +
                      std::to_string(kManufacturerKey) + " or " +
                      std::to_string(kManufacturerKeySigned) + ")"};
  }
  if (value.size() < kValueSize) {
    return Unexpected{"manufacturer data value has " + std::to_string(value.size()) +
                      " bytes, an Anki car sends " + std::to_string(kValueSize) + " after the key"};
  }
  return fromValue(value);
}

LocalName parseLocalName(std::span<const std::uint8_t> raw) {
  // anki-overdrive.md: [0] state bits, [1..2] version LE, [3..7] reserved, [8..] name, NUL-ended.
  LocalName name;
  if (raw.size() >= 1) {
    name.full_battery = (raw[0] & 0x10) != 0;
    name.low_battery = (raw[0] & 0x20) != 0;
    name.on_charger = (raw[0] & 0x40) != 0;
  }
  if (raw.size() >= 3) name.version = static_cast<std::uint16_t>(raw[1] | (raw[2] << 8));
  if (raw.size() > 8) {
    auto rest = raw.subspan(8);
    std::size_t end = 0;
    while (end < rest.size() && rest[end] != 0) ++end;
    name.user_name = utf8OrReplacement(rest.first(end));
  }
  return name;
}

bool isAnkiLocalName(std::span<const std::uint8_t> raw) {
  if (raw.size() < 8 || (raw[0] & ~0x70u) != 0) return false;
  // Real cars' reserved bytes are not all zero, as drive-sdk says: both captured names
  // (tests/realdata/advertisements) have 01 and then spaces and letters (01 20 20 5a 39,
  // 01 20 20 20 20). Their first is a control character, which no text name has.
  return raw[3] < 0x20;
}

std::string userNameProblem(std::string_view name) {
  if (name.empty()) return "a car's name cannot be empty";
  if (name.size() > kMaxUserNameBytes) {
    return "\"" + std::string(name) + "\" has " + std::to_string(name.size()) +
           " bytes; a car's name has at most " + std::to_string(kMaxUserNameBytes) +
           " (its local name is 20 bytes, 8 of them before the name)";
  }
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(name.data()),
                                            name.size());
  for (std::size_t i = 0; i < bytes.size();) {
    const std::size_t n = utf8Sequence(bytes, i);
    if (n == 0) return "a car's name must be UTF-8: byte " + std::to_string(i) + " is not";
    if (n == 1 && (bytes[i] < 0x20 || bytes[i] == 0x7f)) {
      return "a car's name cannot hold control characters (byte " + std::to_string(i) + ")";
    }
    i += n;
  }
  return "";
}

Result<std::string, std::string> localNameText(const LocalName& name) {
  const auto state =
      static_cast<std::uint8_t>((name.full_battery ? 0x10 : 0) | (name.low_battery ? 0x20 : 0) |
                                (name.on_charger ? 0x40 : 0));
  if (state == 0) {
    return Unexpected{std::string(
        "a state byte with no bit set (battery neither full nor low, not on the charger) is a "
        "NUL, which a text name cannot hold")};
  }
  const auto lo = static_cast<std::uint8_t>(name.version & 0xff);
  const auto hi = static_cast<std::uint8_t>(name.version >> 8);
  for (std::uint8_t b : {lo, hi}) {
    if (b == 0 || b > 0x7f) {
      return Unexpected{"version " + hex16(name.version) +
                        " has a byte that is no character of its own in UTF-8 (0x01..0x7f)"};
    }
  }
  if (auto problem = userNameProblem(name.user_name); !problem.empty()) {
    return Unexpected{std::move(problem)};
  }
  std::string text{static_cast<char>(state), static_cast<char>(lo), static_cast<char>(hi)};
  text.append(5, static_cast<char>(kNameFiller));
  return text + name.user_name;
}

// anki-overdrive.md "Model ids" (majority of sources where they disagree); index = model id,
// empty = no known model.
std::string modelName(std::uint8_t model_id) {
  static constexpr std::array<std::string_view, 21> kModels{
      "",         "Kourai",      "Boson", "Rho",     "Katal",   "Hadion",   "Spektrix",
      "Corax",    "Groundshock", "Skull", "Thermo",  "Nuke",    "Guardian", "",
      "Big Bang", "Free Wheel",  "X52",   "X52 Ice", "Mammoth", "Dynamo",   "Nuke Phantom"};
  if (model_id < kModels.size() && !kModels[model_id].empty()) {
    return std::string(kModels[model_id]);
  }
  return "model-" + std::to_string(model_id);
}

std::string uniqueCarName(std::uint8_t model_id, const std::vector<std::string>& taken) {
  std::string base = anki::modelName(model_id);
  std::transform(base.begin(), base.end(), base.begin(), [](unsigned char c) {
    return c == ' ' ? '-' : static_cast<char>(std::tolower(c));
  });
  std::string name = base;
  for (int n = 2; std::find(taken.begin(), taken.end(), name) != taken.end(); ++n)
    name = base + "-" + std::to_string(n);
  return name;
}

}  // namespace pitwall::anki
