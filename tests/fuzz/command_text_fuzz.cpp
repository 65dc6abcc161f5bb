// The command-text parsers of `pitwall encode` (engine/protocol/*/command_text.hpp): words a user
// types, any bytes. The first input byte picks the protocol (Anki, MindRoad, Alphabot); the rest
// is split into words at spaces. Never a crash or an exception (numbers are parsed without
// throwing); a refusal is a sentence. An accepted command is in range and survives the wire:
// - Anki: limits::validate accepts it, and encode → decode gives the same frame back;
// - MindRoad: validate accepts it, and encode → decode gives the same instruction;
// - Alphabot: the WLAN encoding decodes to the same request in both byte orders.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "engine/protocol/alphabot/command_text.hpp"
#include "engine/protocol/alphabot/wlan_codec.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "engine/protocol/anki/command_text.hpp"
#include "engine/protocol/anki/limits.hpp"
#include "engine/protocol/mindroad/codec.hpp"
#include "engine/protocol/mindroad/command_text.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;

namespace {

std::string joined(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : " ") + w;
  return out;
}

void ankiCommand(const std::vector<std::string>& words) {
  auto m = anki::parseCommand(words);
  if (!m) {
    FUZZ_CHECK(!m.error().empty(), joined(words));
    return;
  }
  FUZZ_CHECK(!anki::limits::validate(*m), joined(words) + ": " + *anki::limits::validate(*m));
  const anki::Frame f = anki::encode(*m);
  auto back = anki::decode(f.span());
  FUZZ_CHECK(back.ok() && anki::encode(*back) == f, joined(words));
}

void mindroadCommand(const std::vector<std::string>& words) {
  auto m = mindroad::parseCommand(words);
  if (!m) {
    FUZZ_CHECK(!m.error().empty(), joined(words));
    return;
  }
  FUZZ_CHECK(!mindroad::validate(*m), joined(words));
  const mindroad::Frame f = mindroad::encode(*m);
  auto back = mindroad::decode(f.span());
  FUZZ_CHECK(back.ok() && *back == *m, joined(words));
}

void alphabotRequest(const std::vector<std::string>& words) {
  auto r = alphabot::parseRequest(words);
  if (!r) {
    FUZZ_CHECK(!r.error().empty(), joined(words));
    return;
  }
  for (auto order : {alphabot::wlan::ByteOrder::Little, alphabot::wlan::ByteOrder::Big}) {
    const auto bytes = alphabot::wlan::encode(*r, {order});
    auto back = alphabot::wlan::decode(bytes, {order});
    FUZZ_CHECK(back.ok() && std::holds_alternative<alphabot::Request>(*back) &&
                   std::get<alphabot::Request>(*back) == *r,
               joined(words));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  std::vector<std::string> words(1);
  for (std::size_t i = 1; i < size; ++i) {
    if (data[i] == ' ') {
      words.emplace_back();
    } else {
      words.back().push_back(static_cast<char>(data[i]));
    }
  }
  if (words.size() == 1 && words[0].empty()) words.clear();
  switch (data[0] % 3) {
    case 0:
      ankiCommand(words);
      break;
    case 1:
      mindroadCommand(words);
      break;
    default:
      alphabotRequest(words);
  }
  return 0;
}
