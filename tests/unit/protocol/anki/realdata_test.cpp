// Every frame real cars sent (tests/realdata: okoeth's car, IBM's 0x266e examples, two
// advertisements) is read by the codec with nothing malformed, unknown or left over.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "engine/core/hex.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/protocol/anki/codec.hpp"

using namespace pitwall;
using namespace pitwall::anki;

namespace {

const std::string kDir = PITWALL_SOURCE_DIR "/tests/realdata/";

struct Line {
  std::string where;  // file:line
  std::vector<std::uint8_t> bytes;
};

// `index car hex…` lines.
std::vector<Line> framesOf(const std::string& path) {
  std::ifstream in(path);
  REQUIRE_MESSAGE(in, path);
  std::vector<Line> out;
  int number = 0;
  for (std::string text; std::getline(in, text);) {
    ++number;
    std::istringstream words(text);
    std::string index, car, digits, hex;
    words >> index >> car;
    while (words >> hex) digits += hex;
    auto bytes = fromHex(digits);
    REQUIRE_MESSAGE(bytes.ok(), path << ":" << number);
    out.push_back({path.substr(kDir.size()) + ":" + std::to_string(number), *bytes});
  }
  return out;
}

std::vector<Line> carFrames() {
  std::vector<Line> all = framesOf(kDir + "ibm/messages.txt");
  for (const auto& entry : std::filesystem::directory_iterator(kDir + "okoeth")) {
    const std::string name = entry.path().filename().string();
    if (name.ends_with(".txt") && !name.ends_with(".commands.txt") && name != "PROVENANCE.txt")
      for (auto& l : framesOf(entry.path().string())) all.push_back(std::move(l));
  }
  return all;
}

}  // namespace

TEST_CASE("every notification real cars sent decodes, none unknown, none with bytes left over") {
  std::map<std::string, int> kinds;
  const auto frames = carFrames();
  CHECK(frames.size() >= 300);  // okoeth's 8 runs (294) and IBM's 13
  for (const auto& f : frames) {
    INFO(f.where << ": " << toHex(f.bytes));
    auto m = decode(f.bytes);
    REQUIRE(m.ok());
    CHECK_FALSE(std::holds_alternative<Unknown>(*m));
    CHECK(extraBytes(f.bytes).empty());
    ++kinds[std::string(name(*m))];
  }
  for (const char* kind : {"position-update", "transition-update", "speed-update", "car-status",
                           "lane-change-update", "collision", "cycle-overtime", "version-response",
                           "delocalized", "offset-update", "auto-recovery-entered"})
    CHECK_MESSAGE(kinds[kind] >= 1, kind);
}

TEST_CASE("the two families' transition updates: a driving direction from 0x266e only") {
  int older = 0, newer = 0;
  for (const auto& f : carFrames()) {
    auto m = decode(f.bytes);
    REQUIRE(m.ok());
    if (auto* t = std::get_if<TransitionUpdate>(&*m)) {
      INFO(f.where);
      const bool ibm = f.where.starts_with("ibm/");
      CHECK(t->driving_direction.has_value() == ibm);
      CHECK(f.bytes.size() == (ibm ? 19u : 18u));
      CHECK(t->piece_idx == 0);  // always 0 on real cars
      (ibm ? older : newer)++;
    }
  }
  CHECK(older == 1);
  CHECK(newer == 99);
}

// Advertising records: AD structures [length][type][data]; type 0xff manufacturer data, 0x09 the
// complete local name.
TEST_CASE("the advertisements real cars sent give their model, identifier, version and name") {
  struct Expect {
    int model;
    std::uint32_t identifier;
    std::uint16_t version;
    std::string name;
  };
  std::map<std::string, Expect> found;
  std::string lastCar;
  for (const auto& f : framesOf(kDir + "advertisements/messages.txt")) {
    INFO(f.where);
    for (std::size_t at = 0; at < f.bytes.size();) {
      const std::size_t length = f.bytes[at];
      if (length == 0) break;
      REQUIRE(at + 1 + length <= f.bytes.size());
      const std::uint8_t type = f.bytes[at + 1];
      std::span<const std::uint8_t> data(f.bytes.data() + at + 2, length - 1);
      if (type == 0xff) {
        auto md = parseManufacturerData(data);
        REQUIRE(md.ok());
        found[f.where].model = md->model_id;
        found[f.where].identifier = md->identifier;
      } else if (type == 0x09) {
        REQUIRE(isAnkiLocalName(data));
        auto n = parseLocalName(data);
        found[f.where].version = n.version;
        found[f.where].name = n.user_name;
      }
      at += 1 + length;
    }
  }
  REQUIRE(found.size() == 3);
  CHECK(found["advertisements/messages.txt:1"].model == 1);  // Kourai, drive-sdk's capture
  CHECK(found["advertisements/messages.txt:1"].identifier == 0x00e00aa3);
  CHECK(found["advertisements/messages.txt:2"].version == 0x2120);
  CHECK(found["advertisements/messages.txt:2"].name == "AA3 TOMMY");
  CHECK(found["advertisements/messages.txt:3"].model == 19);  // ble_monitor #1256
  CHECK(found["advertisements/messages.txt:3"].identifier == 0x095473d8);
  CHECK(found["advertisements/messages.txt:3"].version == 0x3060);
  CHECK(found["advertisements/messages.txt:3"].name == "Drive");
}
