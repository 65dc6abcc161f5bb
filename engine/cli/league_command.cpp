// pitwall league DIR|FILES…: a tournament of driver files in the simulator (docs/league.md).
// Each driver qualifies alone (its best lap sets its place on every grid), then the heats drawn so
// that every driver meets every other (engine/league/schedule.hpp) are raced, each in a process
// of its own (-j), each driver in a world of its own (docs/drivers.md); points per place and the
// tie rule make the standings (engine/league/scoring.hpp). Results as JSON or CSV (--results) and
// an HTML report (--report) that opens from the file.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <tuple>

#include <nlohmann/json.hpp>

#include "bindings/script_file.hpp"
#include "bindings/world.hpp"
#include "engine/cli/fail.hpp"
#include "engine/cli/league_heat.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/standings_keeping.hpp"
#include "engine/cli/test_pool.hpp"
#include "engine/core/numbers.hpp"
#include "engine/league/report.hpp"
#include "engine/league/schedule.hpp"
#include "engine/league/scoring.hpp"
#include "engine/record/results.hpp"
#include "engine/sim/sensor.hpp"
#include "engine/sim/track.hpp"
#include "engine/standings/keeper.hpp"

namespace pitwall::cli {

namespace fs = std::filesystem;

namespace {

struct LeagueOptions {
  std::vector<std::string> paths;
  int rounds = 1;
  int cars = 4;
  int laps = 5;
  int qualifyingLaps = 2;
  std::string track = "oval";
  std::string sensor = "real";
  int jobs = 1;
  std::uint64_t seed = 1;
  std::string results;
  std::string report;
  DriverLimitOptions limits;
  std::string db;     // --db FILE: the standings database (default: standings::defaultPath())
  bool noDb = false;  // --no-db: keep nothing
  std::string shard;  // K/N: the heats of shard K of N only
  // pitwall league merge FILE…: the shards' results, as one league
  std::vector<std::string> merge;
};

struct Driver {
  std::string name;  // the file's name without .lua
  std::string file;  // absolute
};

// The drivers of DIR (its *.lua files) and FILES, sorted by name; a name given twice or a
// missing file is refused.
Result<std::vector<Driver>, std::string> collect(const std::vector<std::string>& paths) {
  std::vector<Driver> drivers;
  std::map<std::string, std::string> seen;
  auto add = [&](const fs::path& p) -> std::optional<std::string> {
    std::error_code ec;
    Driver d{p.stem().string(), fs::absolute(p, ec).lexically_normal().string()};
    // A file that does not compile still enters: it is out at the start of each of its heats,
    // with the reason in the results (a class's league goes on without it)
    if (auto problem = script_file::check(p.string()))
      std::cerr << "league: " << *problem << ": " << d.name
                << " enters, and is out at the start of each heat\n";
    if (auto it = seen.find(d.name); it != seen.end())
      return "two drivers are named " + d.name + ": " + it->second + " and " + d.file +
             " (a driver's name is its file's: rename one)";
    seen[d.name] = d.file;
    drivers.push_back(std::move(d));
    return std::nullopt;
  };
  for (const auto& given : paths) {
    std::error_code ec;
    if (fs::is_directory(given, ec)) {
      std::vector<fs::path> files;
      for (const auto& e : fs::directory_iterator(given, ec))
        if (e.is_regular_file(ec) && e.path().extension() == ".lua") files.push_back(e.path());
      if (files.empty()) return Unexpected{given + ": no driver files (*.lua) in this folder"};
      std::sort(files.begin(), files.end());
      for (const auto& f : files)
        if (auto problem = add(f)) return Unexpected{*problem};
    } else if (fs::is_regular_file(given, ec)) {
      if (auto problem = add(given)) return Unexpected{*problem};
    } else {
      return Unexpected{given + ": no such file or folder"};
    }
  }
  if (drivers.size() < 2)
    return Unexpected{"a league needs at least 2 drivers, got " + std::to_string(drivers.size())};
  std::sort(drivers.begin(), drivers.end(),
            [](const Driver& a, const Driver& b) { return a.name < b.name; });
  return drivers;
}

std::optional<double> numberAt(const nlohmann::json& row, const char* key) {
  auto it = row.find(key);
  if (it == row.end() || !it->is_number()) return std::nullopt;
  return it->get<double>();
}

nlohmann::json orNull(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

std::string lapText(const std::optional<double>& v) {
  return v ? formatNumber(*v, 3) + " s" : "no time";
}

// A qualifying row and a heat (as --results has them) as races of the standings.
standings::Race qualifyingRace(const nlohmann::json& row, int number, const std::string& file,
                               const nlohmann::json& about) {
  standings::Entry e;
  e.number = 1;
  e.driver = row.value("driver", std::string());
  e.car = row.value("car", std::string());
  e.file = file;
  e.bestLap = numberAt(row, "bestLap");
  e.status = row.value("status", std::string("error"));
  e.finished = e.status == "finished";
  e.reason = row.value("reason", std::string());
  if (e.bestLap) e.position = 1;
  return {"qualifying",
          number,
          about.value("track", std::string()),
          about.value("qualifyingLaps", 0),
          {e}};
}

standings::Race heatRace(const nlohmann::json& heat,
                         const std::map<std::string, std::string>& files,
                         const nlohmann::json& about) {
  standings::Race race{"heat",
                       heat.value("heat", 0),
                       about.value("track", std::string()),
                       about.value("laps", 0),
                       {}};
  if (!heat.contains("results")) return race;
  for (const auto& row : heat["results"]) {
    standings::Entry e;
    e.number = row.value("number", 0);
    e.driver = row.value("driver", std::string());
    e.car = row.value("car", std::string());
    if (auto it = files.find(e.driver); it != files.end()) e.file = it->second;
    if (auto p = numberAt(row, "position")) e.position = static_cast<int>(*p);
    e.finished = row.value("finished", false);
    e.status = row.value("status", std::string(e.finished ? "finished" : "DNF"));
    e.reason = row.value("reason", std::string());
    e.laps = row.value("laps", 0);
    e.bestLap = numberAt(row, "bestLap");
    e.totalTime = numberAt(row, "totalTime");
    if (auto t = row.find("lapTimes"); t != row.end() && t->is_array())
      for (const auto& x : *t)
        if (x.is_number()) e.lapTimes.push_back(x.get<double>());
    race.entries.push_back(std::move(e));
  }
  return race;
}

// The standings database of a league (--db, --no-db): opened before anything races, so a file
// named with --db that cannot take the results refuses the league before it costs anything.
Result<std::unique_ptr<standings::Keeper>, std::string> openKeeper(const LeagueOptions& o,
                                                                   const nlohmann::json& about) {
  return openStandings(o.db, o.noDb,
                       {"league", about.value("title", std::string("league")),
                        about.value("track", std::string()), about.dump()},
                       "league", {{"--results", o.results}, {"--report", o.report}}, std::nullopt);
}

// Says where the standings are, or what was not written (status 1 then).
int finishKeeper(standings::Keeper* keeper) {
  return finishStandings(keeper, "league",
                         [](const std::string& text) { std::cerr << "league: " << text << "\n"; })
             ? 0
             : 1;
}

// K/N with 1 <= K <= N <= 1000.
Result<std::pair<int, int>, std::string> parseShard(const std::string& text) {
  int k = 0, n = 0;
  char slash = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &k, &slash, &n, &extra) != 3 || slash != '/' || n < 1 ||
      n > 1000 || k < 1 || k > n)
    return Unexpected{"--shard " + text +
                      ": expected K/N, shard K of N (1 <= K <= N), as in "
                      "--shard 2/3"};
  return std::pair{k, n};
}

// The standings from the qualifying and heat rows (each row names its driver), printed; the
// league as --results writes it. One way for a run and for a merge of shards.
nlohmann::json complete(nlohmann::json about, const std::vector<Driver>& drivers,
                        nlohmann::json qualifyingRows, nlohmann::json heatRows) {
  const int n = static_cast<int>(drivers.size());
  std::map<std::string, int> index;
  for (int d = 0; d < n; ++d) index[drivers[static_cast<std::size_t>(d)].name] = d;
  std::vector<std::optional<double>> qualifying(static_cast<std::size_t>(n));
  for (const auto& q : qualifyingRows)
    if (auto it = index.find(q.value("driver", std::string())); it != index.end())
      qualifying[static_cast<std::size_t>(it->second)] = numberAt(q, "bestLap");
  std::vector<std::vector<league::Place>> places;
  for (const auto& heat : heatRows) {
    auto& ps = places.emplace_back();
    if (!heat.contains("results")) continue;
    for (const auto& row : heat["results"]) {
      auto it = index.find(row.value("driver", std::string()));
      if (it == index.end()) continue;
      ps.push_back({it->second, row.value("position", 0), row.value("finished", false),
                    numberAt(row, "bestLap")});
    }
  }
  const auto table = league::standings(n, places, qualifying);
  nlohmann::json standingRows = nlohmann::json::array();
  std::cout << "League: " << n << " drivers, " << heatRows.size() << " heats"
            << (about.contains("shard") ? " (shard " + about["shard"].get<std::string>() + ")"
                                        : std::string())
            << "\n";
  std::cout << "POS  DRIVER               POINTS  HEATS  WINS  QUALIFYING\n";
  int position = 0;
  for (const auto& s : table) {
    ++position;
    const auto& d = drivers[static_cast<std::size_t>(s.driver)];
    const int wins = s.places.empty() ? 0 : s.places[0];
    standingRows.push_back({{"position", position},
                            {"driver", d.name},
                            {"file", d.file},
                            {"points", s.points},
                            {"heats", s.heats},
                            {"wins", wins},
                            {"finishes", s.finishes},
                            {"places", s.places},
                            {"bestLap", orNull(s.bestLap)},
                            {"qualifying", orNull(s.qualifying)}});
    char row[160];
    std::snprintf(row, sizeof row, "%3d  %-20s %6d  %5d  %4d  %s\n", position,
                  d.name.substr(0, 20).c_str(), s.points, s.heats, wins,
                  lapText(s.qualifying).c_str());
    std::cout << row;
  }
  return {{"league", std::move(about)},
          {"qualifying", std::move(qualifyingRows)},
          {"heats", std::move(heatRows)},
          {"standings", std::move(standingRows)}};
}

// --results (JSON: everything; CSV: the standings) and --report.
int writeOutputs(const nlohmann::json& all, const LeagueOptions& o) {
  constexpr auto kReplace = nlohmann::json::error_handler_t::replace;  // a reason's bad bytes
  if (!o.results.empty()) {
    Result<bool, std::string> written = true;
    if (auto format = results::formatOf(o.results); format && *format == results::Format::Csv) {
      results::Table t{
          {"position", "driver", "points", "heats", "wins", "finishes", "bestLap", "qualifying"},
          {}};
      auto time = [](const nlohmann::json& v) -> results::Cell {
        if (v.is_number()) return v.get<double>();
        return std::monostate{};
      };
      for (const auto& s : all["standings"])
        t.rows.push_back({s["position"].get<double>(), s["driver"].get<std::string>(),
                          s["points"].get<double>(), s["heats"].get<double>(),
                          s["wins"].get<double>(), s["finishes"].get<double>(), time(s["bestLap"]),
                          time(s["qualifying"])});
      written = results::write(o.results, t);
    } else {
      written = results::writeText(o.results, all.dump(2, ' ', false, kReplace) + "\n", "results");
    }
    if (!written) return fail("league", written.error());
  }
  if (!o.report.empty()) {
    if (auto written = results::writeText(o.report, league::htmlReport(all), "the report");
        !written)
      return fail("league", written.error());
    std::cerr << "league: report " << o.report << "\n";
  }
  return 0;
}

// Checks --results and --report before anything runs: a typo does not cost the league.
int checkOutputs(const LeagueOptions& o) {
  if (!o.results.empty()) {
    if (auto checked = results::writable(o.results); !checked)
      return fail("league", checked.error());
  }
  if (!o.report.empty()) {
    std::error_code ec;
    const fs::path folder = fs::absolute(o.report, ec).parent_path();
    if (!fs::is_directory(folder, ec))
      return fail("league", "--report " + o.report + ": no folder " + folder.string());
  }
  return 0;
}

// pitwall league merge FILE…: the shards' JSON results as the one league they split. Every
// shard of the same league (the same `league` but its shard, the same qualifying), each heat in
// exactly one of them.
int merge(const LeagueOptions& o) {
  if (int status = checkOutputs(o); status != 0) return status;
  nlohmann::json about, qualifying;
  std::map<int, nlohmann::json> heats;
  std::map<std::string, std::string> files;  // driver → file
  std::set<std::string> shardsSeen;
  for (const auto& path : o.merge) {
    std::ifstream in(path);
    auto part = in ? nlohmann::json::parse(in, nullptr, false) : nlohmann::json();
    if (!part.is_object() || !part.contains("league") || !part.contains("heats") ||
        !part.contains("qualifying") || !part.contains("standings"))
      return fail("league", path +
                                ": not the JSON results of a league (pitwall league "
                                "--shard K/N --results FILE.json writes them)");
    nlohmann::json league = part["league"];
    const std::string shard = league.value("shard", std::string("1/1"));
    league.erase("shard");
    if (about.is_null()) {
      about = league;
      qualifying = part["qualifying"];
    } else if (league != about || part["qualifying"] != qualifying) {
      return fail("league", path + ": another league than " + o.merge.front() +
                                " (its drivers, options, seed or qualifying differ)");
    }
    if (!shardsSeen.insert(shard).second)
      return fail("league", path + ": shard " + shard + " is given twice");
    for (const auto& s : part["standings"])
      files[s.value("driver", std::string())] = s.value("file", std::string());
    for (const auto& h : part["heats"]) {
      const int number = h.value("heat", 0);
      if (heats.count(number))
        return fail("league", path + ": heat " + std::to_string(number) + " is in two shards");
      heats[number] = h;
    }
  }
  const int total = about.value("heats", 0);
  for (int h = 1; h <= total; ++h)
    if (!heats.count(h))
      return fail("league", "heat " + std::to_string(h) + " of " + std::to_string(total) +
                                " is in none of the files: merge every shard's results");
  std::vector<Driver> drivers;
  for (const auto& [name, file] : files) drivers.push_back({name, file});
  nlohmann::json heatRows = nlohmann::json::array();
  for (auto& [number, h] : heats) heatRows.push_back(std::move(h));
  auto opened = openKeeper(o, about);
  if (!opened) return fail("league", opened.error());
  const nlohmann::json league = about;
  auto all = complete(std::move(about), drivers, std::move(qualifying), std::move(heatRows));
  if (auto& keeper = *opened) {
    int number = 0;
    for (const auto& q : all["qualifying"])
      keeper->add(qualifyingRace(q, ++number, files[q.value("driver", std::string())], league));
    for (const auto& h : all["heats"]) keeper->add(heatRace(h, files, league));
  }
  const int kept = finishKeeper(opened->get());
  if (int status = writeOutputs(all, o); status != 0) return status;
  return kept;
}

int league(const LeagueOptions& o) {
  if (!o.merge.empty()) return merge(o);
  if (o.paths.empty())
    return fail("league", "give the drivers: files, or folders of them (pitwall league DIR)");
  int shard = 1, shards = 1;
  if (!o.shard.empty()) {
    auto parsed = parseShard(o.shard);
    if (!parsed) return fail("league", parsed.error());
    std::tie(shard, shards) = *parsed;
  }
  auto drivers = collect(o.paths);
  if (!drivers) return fail("league", drivers.error());
  if (auto track = sim::loadLayout(o.track); !track) return fail("league", track.error());
  if (int status = checkOutputs(o); status != 0) return status;
  const int n = static_cast<int>(drivers->size());
  const int perHeat = std::min(o.cars, n);
  const int jobs = std::max(1, o.jobs);
  DriverLimits limits;
  limits.memory = static_cast<std::size_t>(o.limits.driverMemory) << 20;
  limits.budget = std::chrono::milliseconds(std::llround(o.limits.driverBudget * 1000));
  auto spec = [&](std::vector<std::string> files, bool qualifying, std::uint64_t seed,
                  std::string title) {
    HeatSpec s;
    s.files = std::move(files);
    s.qualifying = qualifying;
    s.laps = qualifying ? o.qualifyingLaps : o.laps;
    s.track = o.track;
    s.sensor = o.sensor;
    s.seed = seed;
    s.title = std::move(title);
    s.limits = limits;
    return s;
  };
  int errors = 0;
  const auto heats = league::drawHeats(n, perHeat, o.rounds, o.seed);
  nlohmann::json about = {{"title", fs::path(o.paths.front()).filename().string()},
                          {"drivers", n},
                          {"heats", heats.size()},
                          {"cars", perHeat},
                          {"laps", o.laps},
                          {"qualifyingLaps", o.qualifyingLaps},
                          {"rounds", o.rounds},
                          {"track", o.track},
                          {"seed", o.seed}};
  // The standings (a shard keeps nothing: `league merge` keeps the league it joins)
  std::unique_ptr<standings::Keeper> keeper;
  if (shards == 1) {
    auto opened = openKeeper(o, about);
    if (!opened) return fail("league", opened.error());
    keeper = std::move(*opened);
  }
  std::map<std::string, std::string> files;  // driver → file
  for (const auto& d : *drivers) files[d.name] = d.file;
  auto keep = [&](standings::Race race) {
    if (!keeper) return;
    if (auto held = keeper->add(std::move(race))) std::cerr << "league: " << *held << "\n";
  };

  // Every heat runs in a child of this process (runInWorkers: `-j` children, each running heat
  // after heat): the library is parsed once, here, and each child's worlds load its bytecode
  // (docs/performance.md "Issue 38").
  try {
    compileLibraryAhead();
  } catch (const std::exception&) {  // (no library: the first heat says so, as a sentence)
  }

  // Qualifying: each driver alone, its best lap
  std::vector<std::optional<double>> qualifying(static_cast<std::size_t>(n));
  nlohmann::json qualifyingRows = nlohmann::json::array();
  std::cerr << "league: " << n << " drivers; qualifying (" << o.qualifyingLaps
            << (o.qualifyingLaps == 1 ? " lap" : " laps") << " each)\n";
  runInWorkers(
      static_cast<std::size_t>(n), jobs,
      [&](std::size_t d) {
        return runHeat(spec({(*drivers)[d].file}, true, o.seed * 1000003 + 500000 + d,
                            "Qualifying: " + (*drivers)[d].name));
      },
      [&](std::size_t d, ScenarioResult r) {
        nlohmann::json row = {{"driver", (*drivers)[d].name}};
        if (!r.passed()) {
          ++errors;
          row["status"] = "error";
          row["reason"] = r.message;
        } else {
          auto rows = nlohmann::json::parse(r.data, nullptr, false);
          const nlohmann::json first =
              rows.is_array() && !rows.empty() ? rows[0] : nlohmann::json::object();
          qualifying[d] = numberAt(first, "bestLap");
          row["status"] = first.value("status", "error");
          if (first.contains("reason")) row["reason"] = first["reason"];
          if (first.contains("car")) row["car"] = first["car"];
        }
        row["bestLap"] = orNull(qualifying[d]);
        keep(qualifyingRace(row, static_cast<int>(d + 1), (*drivers)[d].file, about));
        std::cerr << "qualifying " << d + 1 << "/" << n << ": " << (*drivers)[d].name << " "
                  << lapText(qualifying[d])
                  << (row.contains("reason") ? " (" + row["reason"].get<std::string>() + ")" : "")
                  << "\n";
        qualifyingRows.push_back(std::move(row));
      });

  // The heats (this shard's), each grid by qualifying
  std::vector<std::size_t> mine;
  for (std::size_t h = 0; h < heats.size(); ++h)
    if (league::inShard(h, shard, shards)) mine.push_back(h);
  std::vector<std::vector<int>> grids;
  for (const auto& h : heats) grids.push_back(league::gridOrder(h, qualifying));
  nlohmann::json heatRows = nlohmann::json::array();
  std::cerr << "league: " << heats.size() << " heats of " << perHeat << " cars, " << o.laps
            << (o.laps == 1 ? " lap" : " laps")
            << (shards > 1 ? "; shard " + std::to_string(shard) + "/" + std::to_string(shards) +
                                 " races " + std::to_string(mine.size()) + " of them"
                           : std::string())
            << "\n";
  runInWorkers(
      mine.size(), jobs,
      [&](std::size_t i) {
        const std::size_t h = mine[i];
        std::vector<std::string> files;
        for (int d : grids[h]) files.push_back((*drivers)[static_cast<std::size_t>(d)].file);
        return runHeat(spec(files, false, o.seed * 1000003 + h, "Heat " + std::to_string(h + 1)));
      },
      [&](std::size_t i, ScenarioResult r) {
        const std::size_t h = mine[i];
        nlohmann::json heat = {{"heat", h + 1}};
        nlohmann::json names = nlohmann::json::array();
        for (int d : grids[h]) names.push_back((*drivers)[static_cast<std::size_t>(d)].name);
        heat["grid"] = names;
        std::string line = "heat " + std::to_string(h + 1) + "/" + std::to_string(heats.size());
        auto rows = r.passed() ? nlohmann::json::parse(r.data, nullptr, false) : nlohmann::json();
        if (!rows.is_array()) {
          ++errors;
          heat["error"] = r.passed() ? "the heat's results could not be read" : r.message;
          std::cerr << line << ": " << heat["error"].get<std::string>() << "\n";
          heatRows.push_back(std::move(heat));
          return;
        }
        nlohmann::json results = nlohmann::json::array();
        for (auto& row : rows) {
          const int number = row.value("number", 0);
          if (number < 1 || number > static_cast<int>(grids[h].size())) continue;
          const int driver = grids[h][static_cast<std::size_t>(number - 1)];
          const int position = row.value("position", 0);
          const bool finished = row.value("finished", false);
          row["driver"] = (*drivers)[static_cast<std::size_t>(driver)].name;
          row["points"] = league::pointsFor(position, finished);
          line += (results.empty() ? ": " : ", ") + std::to_string(position) + ". " +
                  row["driver"].get<std::string>() +
                  (finished ? "" : " " + row.value("status", std::string("DNF")));
          results.push_back(row);
        }
        heat["results"] = results;
        std::cerr << line << "\n";
        keep(heatRace(heat, files, about));
        heatRows.push_back(std::move(heat));
      });

  if (shards > 1) about["shard"] = std::to_string(shard) + "/" + std::to_string(shards);
  auto all = complete(std::move(about), *drivers, std::move(qualifyingRows), std::move(heatRows));
  const int kept = finishKeeper(keeper.get());
  if (int status = writeOutputs(all, o); status != 0) return status;
  return errors || kept ? 1 : 0;
}

}  // namespace

Command addLeagueCommand(CLI::App& app) {
  auto o = std::make_shared<LeagueOptions>();
  auto* cmd = app.add_subcommand(
      "league",
      "Score driver files in the simulator: qualifying, heats where every driver meets "
      "every other, standings (docs/league.md)");
  cmd->add_option("drivers", o->paths, "Driver files, or folders of them (*.lua)");
  cmd->add_option("--shard", o->shard,
                  "K/N: race only shard K of N of the heats (merge the shards' --results with "
                  "pitwall league merge)");
  auto* merge = cmd->add_subcommand(
      "merge", "Merge the JSON results of a league's shards into the one league they split");
  merge->add_option("files", o->merge, "Each shard's --results FILE.json")->required();
  merge->add_option("--results", o->results, "Write the league as JSON or CSV to FILE");
  merge->add_option("--report", o->report, "Write the HTML report to FILE.html");
  cmd->add_option("--races", o->rounds,
                  "Rounds: in each, every driver meets every other in a heat (default 1)")
      ->check(CLI::Range(1, 100));
  cmd->add_option("--cars", o->cars, "Cars in a heat (default 4)")->check(CLI::Range(1, 16));
  cmd->add_option("--laps", o->laps, "Laps of a heat (default 5)")->check(CLI::Range(1, 100));
  cmd->add_option("--qualifying-laps", o->qualifyingLaps,
                  "Laps each driver drives alone to qualify (default 2)")
      ->check(CLI::Range(1, 20));
  cmd->add_option("--track", o->track, "The layout: a name (oval, …) or a layout file");
  cmd->add_option("--sensor", o->sensor,
                  "The simulated cars' sensors: real (default, as real cars report) or ideal")
      ->check(CLI::IsMember({"real", "ideal"}));
  cmd->add_option("-j,--jobs", o->jobs,
                  "Heats raced at once: N child processes, each racing heat after heat")
      ->check(CLI::Range(1, 256));
  cmd->add_option("--seed", o->seed, "The draw's and the simulator's seed (default 1)");
  cmd->add_option("--results", o->results,
                  "Write the league as JSON (everything) or CSV (the standings) to FILE");
  cmd->add_option("--report", o->report, "Write an HTML report (standings, heats, charts)");
  addStandingsOptions(cmd, o->db, o->noDb, "the league");
  addStandingsOptions(merge, o->db, o->noDb, "the merged league");
  addDriverLimits(cmd, o->limits, "each driver world");
  return {cmd, [o] { return league(*o); }};
}

}  // namespace pitwall::cli
