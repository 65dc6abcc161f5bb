// pitwall standings: the table that lasts across evenings (docs/league.md "Standings"): points,
// races, wins and podiums of every driver in every race and league kept in the database, per
// track or all of them; personal bests; one driver's history; the events; and `import` of races
// that could not be written when they ended.
#include <cstdio>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/standings_keeping.hpp"
#include "engine/core/numbers.hpp"
#include "engine/core/printable.hpp"
#include "engine/standings/database.hpp"
#include "engine/standings/keeper.hpp"

namespace pitwall::cli {

namespace {

struct StandingsOptions {
  std::string db;
  std::string track;
  std::string driver;
  bool events = false;
  bool json = false;
  std::vector<std::string> imports;
};

std::string lap(const std::optional<double>& v) {
  return v ? formatNumber(*v, 3) + " s" : "-";
}

nlohmann::json orNull(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

std::string cut(const std::string& s, std::size_t n) {
  return printable(s, n);
}

int printEvents(standings::Database& db, bool json) {
  auto events = db.events();
  if (!events) return fail("standings", events.error(), 1);
  nlohmann::json rows = nlohmann::json::array();
  if (!json) std::cout << "  ID  KIND    STARTED               RACES  TITLE (TRACK)\n";
  for (const auto& e : *events) {
    rows.push_back({{"id", e.id},
                    {"kind", e.kind},
                    {"title", e.title},
                    {"track", e.track},
                    {"started", e.started},
                    {"ended", e.ended.empty() ? nlohmann::json(nullptr) : nlohmann::json(e.ended)},
                    {"races", e.races}});
    if (json) continue;
    char line[512];
    std::snprintf(line, sizeof line, "%4lld  %-6s  %-20s  %5d  %s (%s)%s\n",
                  static_cast<long long>(e.id), cut(e.kind, 8).c_str(), cut(e.started, 20).c_str(),
                  e.races, cut(e.title, 60).c_str(), cut(e.track, 40).c_str(),
                  e.ended.empty() ? "  not finished" : "");
    std::cout << line;
  }
  if (json) std::cout << rows.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  return 0;
}

int printTable(standings::Database& db, const StandingsOptions& o) {
  standings::Filter f;
  if (!o.track.empty()) f.track = o.track;
  auto table = db.table(f);
  if (!table) return fail("standings", table.error(), 1);
  if (!o.driver.empty()) f.driver = o.driver;
  auto bests = db.bests(f);
  if (!bests) return fail("standings", bests.error(), 1);
  std::optional<std::vector<standings::Past>> history;
  if (!o.driver.empty()) {
    auto h = db.history(o.driver);
    if (!h) return fail("standings", h.error(), 1);
    if (h->empty()) {
      std::string known;
      for (const auto& row : *table) known += (known.empty() ? "" : ", ") + row.driver;
      return fail("standings",
                  "no races of " + o.driver + " in " + db.path() +
                      (known.empty() ? std::string(" (it has none yet)")
                                     : " (its drivers: " + cut(known, 300) + ")"),
                  1);
    }
    history = std::move(*h);
  }
  if (o.json) {
    nlohmann::json out = {{"database", db.path()}};
    if (!o.track.empty()) out["track"] = o.track;
    nlohmann::json rows = nlohmann::json::array();
    int position = 0;
    for (const auto& r : *table)
      rows.push_back({{"position", ++position},
                      {"driver", r.driver},
                      {"points", r.points},
                      {"races", r.races},
                      {"wins", r.wins},
                      {"podiums", r.podiums},
                      {"finishes", r.finishes},
                      {"bestLap", orNull(r.bestLap)}});
    out["standings"] = rows;
    nlohmann::json pbs = nlohmann::json::array();
    for (const auto& b : *bests)
      pbs.push_back({{"driver", b.driver},
                     {"track", b.track},
                     {"lap", b.lap},
                     {"car", b.car},
                     {"when", b.when},
                     {"event", b.event}});
    out["personalBests"] = pbs;
    if (history) {
      nlohmann::json races = nlohmann::json::array();
      for (const auto& p : *history)
        races.push_back({{"when", p.when},
                         {"event", p.event},
                         {"kind", p.kind},
                         {"number", p.number},
                         {"track", p.track},
                         {"car", p.car},
                         {"position", p.position ? nlohmann::json(*p.position) : nullptr},
                         {"status", p.status},
                         {"points", p.points},
                         {"bestLap", orNull(p.bestLap)}});
      out["races"] = races;
    }
    std::cout << out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
    return 0;
  }
  if (history) {
    std::cout << cut(o.driver, 60) << " (" << db.path() << ")\n";
    std::cout << "WHEN                  EVENT                 RACE           TRACK       CAR"
                 "            POS  POINTS  BEST LAP\n";
    for (const auto& p : *history) {
      char line[640];
      std::snprintf(
          line, sizeof line, "%-20s  %-20s  %-13s  %-10s  %-13s  %3s  %6d  %s\n", p.when.c_str(),
          cut(p.event, 20).c_str(), cut(p.kind + " " + std::to_string(p.number), 13).c_str(),
          cut(p.track, 10).c_str(), cut(p.car, 13).c_str(),
          p.position ? std::to_string(*p.position).c_str() : "-", p.points,
          (p.status == "finished" || p.status.empty() ? lap(p.bestLap) : p.status).c_str());
      std::cout << line;
    }
  } else {
    std::cout << "Standings" << (o.track.empty() ? "" : " on " + o.track) << " (" << db.path()
              << ")\n";
    if (table->empty())
      std::cout << "  no races yet" << (o.track.empty() ? "" : " on this track") << "\n";
    else
      std::cout << "POS  DRIVER                POINTS  RACES  WINS  PODIUMS  BEST LAP\n";
    int position = 0;
    for (const auto& r : *table) {
      char line[400];
      std::snprintf(line, sizeof line, "%3d  %-20s  %6d  %5d  %4d  %7d  %s\n", ++position,
                    cut(r.driver, 20).c_str(), r.points, r.races, r.wins, r.podiums,
                    lap(r.bestLap).c_str());
      std::cout << line;
    }
  }
  if (!bests->empty()) {
    std::cout << "\nPersonal bests\n";
    std::cout << "TRACK                 DRIVER                BEST LAP  CAR            SET\n";
    for (const auto& b : *bests) {
      char line[640];
      std::snprintf(line, sizeof line, "%-20s  %-20s  %8s  %-13s  %s (%s)\n",
                    cut(b.track, 20).c_str(), cut(b.driver, 20).c_str(), lap(b.lap).c_str(),
                    cut(b.car, 13).c_str(), cut(b.when, 20).c_str(), cut(b.event, 40).c_str());
      std::cout << line;
    }
  }
  return 0;
}

int standingsCommand(const StandingsOptions& o) {
  const std::string path = o.db.empty() ? standings::defaultPath() : o.db;
  if (!o.imports.empty()) {
    for (const auto& file : o.imports) {
      auto added = standings::importUnsaved(path, file);
      if (!added) return fail("standings", added.error(), 1);
      std::cout << "standings: " << *added << (*added == 1 ? " race" : " races") << " from " << file
                << " added to " << path << "\n";
    }
    return 0;
  }
  auto db = standings::Database::open(path, false);
  if (!db) return fail("standings", db.error(), 1);
  if (o.events) return printEvents(**db, o.json);
  return printTable(**db, o);
}

}  // namespace

Command addStandingsCommand(CLI::App& app) {
  auto o = std::make_shared<StandingsOptions>();
  auto* cmd = app.add_subcommand(
      "standings",
      "The standings kept across evenings: every race's and league's points, wins and personal "
      "bests (docs/league.md)");
  cmd->add_option("--db", o->db,
                  "The standings database (default: $PITWALL_DB, else "
                  "$XDG_DATA_HOME/pitwall/standings.db or ~/.local/share/pitwall/standings.db)")
      ->check(standingsFile());
  cmd->add_option("--track", o->track, "Only the races on this track (its name, as listed)");
  cmd->add_option("--driver", o->driver, "One driver's races and personal bests");
  cmd->add_flag("--events", o->events, "List the events kept: leagues, races, finals");
  cmd->add_flag("--json", o->json, "Print JSON (for tools)");
  auto* import = cmd->add_subcommand(
      "import", "Add the races of an unsaved file (written when the database could not be)");
  import->fallthrough();  // --db after `import` is the command's
  import->add_option("files", o->imports, "The unsaved files (FILE.unsaved-….json)")->required();
  return {cmd, [o] { return standingsCommand(*o); }};
}

}  // namespace pitwall::cli
