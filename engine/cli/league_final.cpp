#include "engine/cli/league_final.hpp"

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "engine/core/data_dir.hpp"
#include "engine/league/scoring.hpp"
#include "engine/standings/database.hpp"

namespace pitwall::cli {

namespace fs = std::filesystem;

Result<FinalPlan, std::string> planFinal(const std::string& given, int cars) {
  FinalPlan plan;
  plan.db = given;
  std::optional<std::int64_t> event;
  // DB:EVENT — a suffix of digits after the last colon (a path may hold colons of its own)
  if (auto colon = given.rfind(':');
      colon != std::string::npos && colon + 1 < given.size() &&
      given.find_first_not_of("0123456789", colon + 1) == std::string::npos &&
      given.size() - colon - 1 <= 12) {
    plan.db = given.substr(0, colon);
    event = std::stoll(given.substr(colon + 1));
  }
  auto db = standings::Database::open(plan.db, false);
  if (!db) return Unexpected{"--league-final " + given + ": " + db.error()};
  auto league = (*db)->league(event);
  if (!league) return Unexpected{"--league-final " + given + ": " + league.error()};
  plan.league = league->event.id;
  plan.title = "Final: " + league->event.title;
  const auto details = nlohmann::json::parse(league->details, nullptr, false);
  if (details.is_object()) {
    plan.laps = details.value("laps", 5);
    if (cars <= 0) cars = details.value("cars", 4);
  }
  if (cars <= 0) cars = 4;
  // The league's standings, by its own rule (engine/league/scoring.hpp)
  const auto& drivers = league->drivers;
  std::map<std::string, int> index;
  std::vector<std::optional<double>> qualifying;
  for (std::size_t d = 0; d < drivers.size(); ++d) {
    index[drivers[d].name] = static_cast<int>(d);
    qualifying.push_back(drivers[d].qualifying);
  }
  std::vector<std::vector<league::Place>> heats;
  for (const auto& heat : league->heats) {
    auto& places = heats.emplace_back();
    for (const auto& p : heat)
      places.push_back({index[p.driver], p.position, p.finished, p.bestLap});
  }
  const auto table = league::standings(static_cast<int>(drivers.size()), heats, qualifying);
  const int k = std::min(cars, static_cast<int>(table.size()));
  if (k < 2)
    return Unexpected{"--league-final " + given + ": league " + std::to_string(plan.league) +
                      " has " + std::to_string(table.size()) +
                      " drivers: a final needs 2 (--final-cars K, K ≥ 2)"};
  for (int i = 0; i < k; ++i) {
    const auto& d = drivers[static_cast<std::size_t>(table[static_cast<std::size_t>(i)].driver)];
    std::error_code ec;
    if (d.file.empty() || !fs::is_regular_file(d.file, ec))
      return Unexpected{"--league-final " + given + ": " + d.name + " (place " +
                        std::to_string(i + 1) + " of the league) drove " +
                        (d.file.empty() ? std::string("a file the database does not name")
                                        : d.file + ", which is not there any more") +
                        ": put the file back where it was, or race fewer with --final-cars " +
                        std::to_string(i)};
    plan.drivers.push_back(d.name);
    plan.files[i + 1] = d.file;
  }
  auto data = dataDir();
  if (!data) return Unexpected{data.error()};
  plan.script = (*data / "scripts" / "pitwall" / "league_final.lua").string();
  return plan;
}

}  // namespace pitwall::cli
