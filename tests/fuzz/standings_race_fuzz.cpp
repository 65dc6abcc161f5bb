// A race's results as JSON (engine/standings/race_json.hpp): what a script hands
// pitwall.keepResults and what an unsaved standings file holds for `pitwall standings import` —
// any bytes. Never a crash or an exception; a refusal is a sentence. An accepted race has a driver
// for every entry and only finite times, and written back as JSON it reads as the same race.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "engine/standings/race_json.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const auto json = nlohmann::json::parse(text, nullptr, false);
  if (json.is_discarded()) return 0;
  auto race = standings::raceFromJson(json);
  if (!race) {
    FUZZ_CHECK(!race.error().empty(), text);
    return 0;
  }
  for (const auto& e : race->entries) {
    FUZZ_CHECK(!e.driver.empty(), text);
    FUZZ_CHECK(!e.bestLap || std::isfinite(*e.bestLap), text);
    FUZZ_CHECK(!e.totalTime || std::isfinite(*e.totalTime), text);
    for (double t : e.lapTimes) FUZZ_CHECK(std::isfinite(t), text);
  }
  const auto again = standings::raceFromJson(standings::toJson(*race));
  FUZZ_CHECK(again.ok(), text);
  FUZZ_CHECK(standings::toJson(*again) == standings::toJson(*race), text);
  auto event = standings::eventFromJson(json);
  if (!event) FUZZ_CHECK(!event.error().empty(), text);
  return 0;
}
