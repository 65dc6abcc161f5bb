#include "engine/view/lap_compare.hpp"

#include <charconv>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "engine/core/printable.hpp"
#include "engine/laps/compare_report.hpp"

namespace pitwall::view {

namespace {

// "CAR:LAP" (the colon may come percent-encoded, "%3A"), both whole numbers of at most 6 digits.
std::optional<std::pair<int, int>> carLap(std::string_view given) {
  std::string decoded(given);
  for (auto at = decoded.find('%'); at != std::string::npos; at = decoded.find('%', at + 1))
    if (decoded.compare(at, 3, "%3A") == 0 || decoded.compare(at, 3, "%3a") == 0)
      decoded.replace(at, 3, ":");
  const std::string_view v = decoded;
  const auto colon = v.find(':');
  if (colon == std::string_view::npos || colon == 0 || colon > 6 || v.size() - colon - 1 > 6 ||
      colon + 1 == v.size())
    return std::nullopt;
  int car = 0, lap = 0;
  auto a = std::from_chars(v.data(), v.data() + colon, car);
  auto b = std::from_chars(v.data() + colon + 1, v.data() + v.size(), lap);
  if (a.ec != std::errc{} || a.ptr != v.data() + colon || b.ec != std::errc{} ||
      b.ptr != v.data() + v.size() || car < 1 || lap < 1)
    return std::nullopt;
  return std::pair{car, lap};
}

}  // namespace

nlohmann::json lapList(const Feed& feed) {
  nlohmann::json cars = nlohmann::json::array();
  for (const auto& [number, name] : feed.tracedCars()) {
    nlohmann::json laps = nlohmann::json::array();
    if (const auto* kept = feed.laps(number))
      for (const auto& l : *kept)
        laps.push_back(
            {{"lap", l.lap}, {"time", std::round(l.time * 1000) / 1000}, {"clean", l.clean}});
    cars.push_back({{"number", number}, {"name", name}, {"laps", std::move(laps)}});
  }
  return {{"cars", std::move(cars)}};
}

Result<nlohmann::json, std::string> compareLaps(const Feed& feed, std::string_view query) {
  if (!feed.track()) return Unexpected{std::string("no track is known, so no lap is placed")};
  std::optional<std::pair<int, int>> a, b;
  while (!query.empty()) {
    const auto amp = query.find('&');
    const std::string_view part = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view{} : query.substr(amp + 1);
    if (part.starts_with("a="))
      a = carLap(part.substr(2));
    else if (part.starts_with("b="))
      b = carLap(part.substr(2));
  }
  if (!a || !b)
    return Unexpected{
        std::string("give two laps as ?a=CAR:LAP&b=CAR:LAP (numbers, e.g. a=1:3&b=2:3)")};
  std::vector<laps::ComparedLap> picked;
  for (const auto& [car, lap] : {*a, *b}) {
    const auto* kept = feed.laps(car);
    const laps::LapTrace* found = nullptr;
    if (kept)
      for (const auto& l : *kept)
        if (l.lap == lap) found = &l;
    if (!found)
      return Unexpected{"car " + std::to_string(car) + " has no traced lap " + std::to_string(lap) +
                        " (GET /api/laps lists the laps there are)"};
    std::string name;
    for (const auto& [number, n] : feed.tracedCars())
      if (number == car) name = n;
    picked.push_back(
        {"car " + std::to_string(car) + " (" + printable(name) + ") lap " + std::to_string(lap),
         found});
  }
  const sim::Track& track = *feed.track();
  laps::LapMap map(track);
  laps::Report report;
  report.laps = std::move(picked);
  report.track = track.name();
  report.sections = laps::sections(track, map);
  report.comparison =
      laps::compare({report.laps[0].trace, report.laps[1].trace}, map, report.sections, 10);
  nlohmann::json j = nlohmann::json::parse(
      laps::reportJson(report).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  j["svg"] = laps::reportSvg(report);
  return j;
}

}  // namespace pitwall::view
