#include "engine/cli/league_final.hpp"

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "engine/core/data_dir.hpp"
#include "engine/core/printable.hpp"
#include "engine/league/scoring.hpp"
#include "engine/standings/database.hpp"

namespace pitwall::cli {

namespace fs = std::filesystem;

Result<FinalPlan, std::string> planFinal(const std::string& given, int cars) {
  FinalPlan plan;
  plan.db = given;
  std::optional<std::int64_t> event;
  // DB:LEAGUE — what follows the last colon, when the whole is no file (a path may hold colons)
  std::error_code ec;
  if (auto colon = given.rfind(':'); colon != std::string::npos && !fs::exists(given, ec)) {
    const std::string id = given.substr(colon + 1);
    if (id.empty() || id.size() > 12 || id.find_first_not_of("0123456789") != std::string::npos)
      return Unexpected{"--league-final " + printable(given, 200) +
                        ": LEAGUE in DB:LEAGUE must be a league's number (pitwall standings --db "
                        "DB --events lists them), got " +
                        printable(id, 40)};
    plan.db = given.substr(0, colon);
    event = std::stoll(id);
  }
  auto db = standings::Database::open(plan.db, false);
  if (!db) return Unexpected{"--league-final " + given + ": " + db.error()};
  auto league = (*db)->league(event);
  if (!league) return Unexpected{"--league-final " + given + ": " + league.error()};
  plan.league = league->event.id;
  plan.title = "Final: " + league->event.title;
  // Its laps and cars a heat, as the league kept them (a number from 1 to 100 and 2 to 64, or
  // the defaults: a database may hold anything)
  const auto details = nlohmann::json::parse(league->details, nullptr, false);
  auto number = [&](const char* key, int fallback, int lo, int hi) {
    if (!details.is_object()) return fallback;
    auto it = details.find(key);
    if (it == details.end() || !it->is_number_integer()) return fallback;
    const auto v = it->get<std::int64_t>();
    return v >= lo && v <= hi ? static_cast<int>(v) : fallback;
  };
  plan.laps = number("laps", 5, 1, 100);
  if (cars <= 0) cars = std::max(2, number("cars", 4, 1, 64));
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
                      (table.size() == 1 ? " driver" : " drivers") + ": a final needs 2"};
  for (int i = 0; i < k; ++i) {
    const auto& d = drivers[static_cast<std::size_t>(table[static_cast<std::size_t>(i)].driver)];
    ec.clear();
    if (d.file.empty() || !fs::is_regular_file(d.file, ec))
      return Unexpected{"--league-final " + printable(given, 200) + ": " + printable(d.name, 60) +
                        " (place " + std::to_string(i + 1) + " of the league) drove " +
                        (d.file.empty()
                             ? std::string("a file the database does not name")
                             : printable(d.file, 200) + ", which is not there any more") +
                        ": put the file back where it was" +
                        (i >= 2 ? ", or race the first " + std::to_string(i) +
                                      " with --final-cars " + std::to_string(i)
                                : std::string())};
    plan.drivers.push_back(printable(d.name, 60));
    plan.files[i + 1] = d.file;
  }
  auto data = dataDir();
  if (!data) return Unexpected{data.error()};
  plan.script = (*data / "scripts" / "pitwall" / "league_final.lua").string();
  return plan;
}

}  // namespace pitwall::cli
