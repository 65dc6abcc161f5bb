// The standings database (engine/standings/database.hpp) and a race's JSON form
// (engine/standings/race_json.hpp): what is written reads back; the table's order; points only
// for races; hostile JSON from a script is a sentence naming the field, never a crash or a row.
#include "engine/standings/database.hpp"

#include <doctest/doctest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "engine/standings/keeper.hpp"
#include "engine/standings/race_json.hpp"

using namespace pitwall::standings;
namespace fs = std::filesystem;

namespace {

struct TempDb {
  fs::path dir = fs::temp_directory_path() / ("pitwall-db-" + std::to_string(::getpid()));
  std::string path = (dir / "s.db").string();
  TempDb() {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~TempDb() { fs::remove_all(dir); }
};

Entry entry(int number, std::string driver, int position, bool finished, double best) {
  Entry e;
  e.number = number;
  e.driver = driver;
  e.car = "car" + std::to_string(number);
  e.position = position;
  e.finished = finished;
  e.status = finished ? "finished" : "DNF";
  e.laps = finished ? 3 : 1;
  e.bestLap = best;
  e.lapTimes = {best + 0.5, best, best + 0.25};
  return e;
}

// SQL run on the file as another program would.
void sqlOn(const std::string& path, const char* sql) {
  sqlite3* raw = nullptr;
  REQUIRE(sqlite3_open(path.c_str(), &raw) == SQLITE_OK);
  CHECK(sqlite3_exec(raw, sql, nullptr, nullptr, nullptr) == SQLITE_OK);
  sqlite3_close(raw);
}

}  // namespace

TEST_CASE("standings: points for races, heats and finals only") {
  CHECK(pointsFor("race", 1, true) == 25);
  CHECK(pointsFor("heat", 2, true) == 18);
  CHECK(pointsFor("final", 10, true) == 1);
  CHECK(pointsFor("final", 11, true) == 0);
  CHECK(pointsFor("race", 1, false) == 0);
  CHECK(pointsFor("qualifying", 1, true) == 0);
  CHECK(pointsFor("practice", 1, true) == 0);
  CHECK(pointsFor("stopped", 1, true) == 0);
  CHECK(pointsFor("race", std::nullopt, true) == 0);
}

TEST_CASE("standings: races kept read back as the table, the bests and a driver's history") {
  TempDb t;
  auto db = Database::open(t.path);
  REQUIRE(db);
  CHECK((*db)->versionFound() == 0);
  auto event = (*db)->beginEvent({"league", "class", "oval", "{}"});
  REQUIRE(event);
  REQUIRE((*db)->addRace(*event, {"qualifying", 1, "oval", 1, {entry(1, "ann", 1, true, 3.1)}}));
  REQUIRE((*db)->addRace(*event, {"heat",
                                  1,
                                  "oval",
                                  3,
                                  {entry(1, "ann", 2, true, 3.3), entry(2, "bo", 1, true, 3.2),
                                   entry(3, "cy", 3, false, 4.0)}}));
  REQUIRE((*db)->addRace(
      *event,
      {"heat", 2, "bowtie", 3, {entry(1, "cy", 1, true, 5.0), entry(2, "ann", 2, true, 4.9)}}));
  REQUIRE((*db)->endEvent(*event));

  auto table = (*db)->table({});
  REQUIRE(table);
  REQUIRE(table->size() == 3);
  // ann: 18 + 18 = 36; cy: 0 + 25; bo: 25 — bo and cy tie on points and wins: the best lap
  CHECK((*table)[0].driver == "ann");
  CHECK((*table)[0].points == 36);
  CHECK((*table)[0].races == 2);  // qualifying is no race
  CHECK((*table)[0].podiums == 2);
  CHECK((*table)[0].bestLap == doctest::Approx(3.1));  // its qualifying lap
  CHECK((*table)[1].driver == "bo");
  CHECK((*table)[2].driver == "cy");
  CHECK((*table)[2].finishes == 1);

  auto oval = (*db)->table({std::string("oval"), std::nullopt, std::nullopt});
  REQUIRE(oval);
  CHECK(oval->size() == 3);
  CHECK((*oval)[0].driver == "bo");  // 25 on the oval

  auto bests = (*db)->bests({std::nullopt, std::string("ann"), std::nullopt});
  REQUIRE(bests);
  REQUIRE(bests->size() == 2);  // one per track
  CHECK((*bests)[0].track == "bowtie");
  CHECK((*bests)[0].lap == doctest::Approx(4.9));
  CHECK((*bests)[1].lap == doctest::Approx(3.1));
  CHECK((*bests)[1].event == "class");

  auto history = (*db)->history("cy");
  REQUIRE(history);
  REQUIRE(history->size() == 2);
  CHECK((*history)[0].status == "DNF");
  CHECK((*history)[1].points == 25);

  auto league = (*db)->league(std::nullopt);
  REQUIRE(league);
  CHECK(league->drivers.size() == 3);
  CHECK(league->drivers[0].name == "ann");
  CHECK(league->drivers[0].qualifying == doctest::Approx(3.1));
  CHECK(league->heats.size() == 2);

  // a race is kept once
  auto again = (*db)->addRace(*event, {"heat", 1, "oval", 3, {entry(1, "ann", 1, true, 3.0)}});
  REQUIRE_FALSE(again);
  CHECK(again.error().find("has that race already") != std::string::npos);
  // a database opened again is at the current version, and keeps what it had
  db = Database::open(t.path);
  REQUIRE(db);
  CHECK((*db)->versionFound() == kSchemaVersion);
  CHECK((*db)->table({})->size() == 3);
}

TEST_CASE("standings: a race's JSON from a script: hostile values are sentences naming the field") {
  nlohmann::json good = {
      {"kind", "race"},
      {"track", "oval"},
      {"laps", 3},
      {"entries",
       {{{"number", 1}, {"car", "skull"}, {"position", 1}, {"finished", true}, {"laps", 3}}}}};
  auto race = raceFromJson(good);
  REQUIRE(race);
  CHECK(race->entries[0].driver == "skull");  // no driver: the car
  CHECK(race->entries[0].status == "finished");
  CHECK(toJson(*race)["entries"][0]["driver"] == "skull");
  CHECK(raceFromJson(toJson(*race))->entries[0].car == "skull");

  struct Bad {
    nlohmann::json patch;
    const char* says;
  };
  const Bad bads[] = {
      {{{"kind", 5}}, "race.kind must be a string"},
      {{{"laps", 1e300}}, "race.laps must be a whole number up to 2147483647, got 1e+300"},
      {{{"laps", "x"}}, "race.laps must be a whole number"},
      {{{"laps", 2.5}}, "race.laps must be a whole number"},
      {{{"entries", "many"}}, "race.entries must be a list"},
      {{{"entries", {7}}}, "race.entries[1] must be an object"},
      {{{"entries", {{{"position", 1e18}, {"car", "a"}}}}}, "race.entries[1].position"},
      {{{"entries", {{{"bestLap", "fast"}, {"car", "a"}}}}}, "race.entries[1].bestLap"},
      {{{"entries", {{{"finished", 1}, {"car", "a"}}}}},
       "race.entries[1].finished must be true or false"},
      {{{"entries", {{{"position", 2}, {"car", "a"}}}}},
       "race.entries[1].position must be a place from 1 to 1 (the race's entries), got 2"},
      {{{"entries", {{{"number", 1}, {"car", "a"}}, {{"number", 1}, {"car", "b"}}}}},
       "race.entries[2].number 1 is another entry's"},
      {{{"kind", nlohmann::json::parse(std::string(1000, '[') + std::string(1000, ']'))}},
       "race.kind must be a string, got a list"},
      {{{"entries", {{{"lapTimes", {1, "x"}}, {"car", "a"}}}}},
       "lapTimes must be a list of seconds"},
      {{{"entries", {{{"number", 2}}}}}, "names no driver and no car"},
  };
  for (const auto& bad : bads) {
    nlohmann::json j = good;
    j.merge_patch(bad.patch);
    auto r = raceFromJson(j);
    CAPTURE(j.dump());
    REQUIRE_FALSE(r);
    CHECK(r.error().find(bad.says) != std::string::npos);
  }
  CHECK_FALSE(raceFromJson(nlohmann::json::array()));
  CHECK_FALSE(raceFromJson(nullptr));
}

TEST_CASE("standings: names of any bytes are kept as they came") {
  TempDb t;
  auto db = Database::open(t.path);
  REQUIRE(db);
  auto event = (*db)->beginEvent({"race", "x", "", "{}"});
  REQUIRE(event);
  const std::string odd = std::string("b\xff\xfe") + '\0' + "d'; DROP TABLE results; --";
  REQUIRE((*db)->addRace(*event, {"race", 1, "oval", 1, {entry(1, odd, 1, true, 3.0)}}));
  auto table = (*db)->table({});
  REQUIRE(table);
  REQUIRE(table->size() == 1);
  CHECK((*table)[0].driver == odd);
}

TEST_CASE("standings: files that hold no standings are sentences, and are left as they were") {
  TempDb t;
  {
    std::ofstream noise(t.path, std::ios::binary);
    for (int i = 0; i < 5000; ++i) noise.put(static_cast<char>(i * 7919 % 251));
  }
  const auto before = fs::file_size(t.path);
  auto db = Database::open(t.path);
  REQUIRE_FALSE(db);
  CHECK(db.error().find("is not a pitwall standings database") != std::string::npos);
  CHECK(fs::file_size(t.path) == before);

  auto missing = Database::open((t.dir / "none.db").string(), false);
  REQUIRE_FALSE(missing);
  CHECK(missing.error().find("yet: a race or a league writes them") != std::string::npos);
  CHECK_FALSE(fs::exists(t.dir / "none.db"));

  auto folder = Database::open(t.dir.string());
  REQUIRE_FALSE(folder);
  CHECK(folder.error().find("is a folder") != std::string::npos);
  auto empty = Database::open("");
  REQUIRE_FALSE(empty);
  CHECK(empty.error().find("no standings database") != std::string::npos);
}

TEST_CASE("standings: a keeper writes each race as it comes, and nothing for a run without one") {
  TempDb t;
  {
    auto keeper = Keeper::open(t.path, {"race", "run", "", "{}"});
    REQUIRE(keeper);
    CHECK_FALSE((*keeper)->finish());
  }
  CHECK((*Database::open(t.path))->events()->empty());
  auto keeper = Keeper::open(t.path, {"race", "run", "", "{}"});
  REQUIRE(keeper);
  CHECK_FALSE((*keeper)->add({"race", 1, "oval", 3, {entry(1, "ann", 1, true, 3.0)}}));
  CHECK((*keeper)->written() == 1);
  // written before the run ends: another reader sees it now
  auto events = (*Database::open(t.path))->events();
  REQUIRE(events->size() == 1);
  CHECK(events->front().ended.empty());
  CHECK(events->front().track == "oval");  // the event's track: its races'
  CHECK_FALSE((*keeper)->finish());
  CHECK_FALSE((*Database::open(t.path))->events()->front().ended.empty());
}

TEST_CASE(
    "standings: a script's second race of a kind gets the next number, and a bad one holds "
    "no other back") {
  TempDb t;
  auto keeper = Keeper::open(t.path, {"race", "run", "", "{}"});
  REQUIRE(keeper);
  CHECK_FALSE((*keeper)->add({"race", 1, "oval", 3, {entry(1, "ann", 1, true, 3.0)}}));
  CHECK_FALSE((*keeper)->add({"race", 1, "oval", 3, {entry(1, "ann", 1, true, 2.9)}}));
  CHECK_FALSE((*keeper)->add({"qualifying", 1, "oval", 1, {entry(1, "ann", 1, true, 2.8)}}));
  CHECK((*keeper)->written() == 3);
  // a race that is not one (a script's own call) is kept as it came, beside the database
  (*keeper)->reject(nlohmann::json{{"kind", 5}}, "race.kind must be a string, got 5");
  auto finished = (*keeper)->finish();
  REQUIRE(finished);
  CHECK(finished->find("not races (race.kind must be a string, got 5): kept in") !=
        std::string::npos);
  auto table = (*Database::open(t.path))->table({});
  REQUIRE(table);
  CHECK(table->front().races == 2);
  CHECK(table->front().points == 50);
}

TEST_CASE("standings: a schema version below zero, or a table removed, is a sentence") {
  TempDb t;
  REQUIRE(Database::open(t.path));
  sqlOn(t.path, "PRAGMA user_version = -2147483648");
  auto negative = Database::open(t.path);
  REQUIRE_FALSE(negative);
  CHECK(negative.error().find("has schema version -2147483648, which no pitwall writes") !=
        std::string::npos);
  sqlOn(t.path, "PRAGMA user_version = 3; DROP TABLE laps");
  auto dropped = Database::open(t.path);
  REQUIRE_FALSE(dropped);
  CHECK(dropped.error().find("but no table laps") != std::string::npos);
}

namespace {
// The fastest kept on `layout` of `who`, none when none is kept.
std::optional<KeptLap> fastest(Database& db, const std::string& layout, const std::string& who) {
  auto all = db.bestLaps(layout, who);
  REQUIRE(all);
  if (all->empty()) return std::nullopt;
  return all->front();
}

Entry traced(int number, std::string driver, double best) {
  Entry e = entry(number, std::move(driver), number, true, best);
  e.bestTrace = Entry::Trace{best, "{\"time\":" + std::to_string(best) + "}"};
  return e;
}
}  // namespace

TEST_CASE("standings: personal bests — each driver's best lap in each car on each layout") {
  TempDb t;
  auto db = Database::open(t.path);
  REQUIRE(db);
  auto event = (*db)->beginEvent({"race", "night", "oval", "{}"});
  REQUIRE(event);
  auto race = [&](int number, std::string layout, std::vector<Entry> entries) {
    Race r{"race", number, "oval", 3, std::move(entries)};
    r.layout = std::move(layout);
    REQUIRE((*db)->addRace(*event, r));
  };
  race(1, "start S L L S L L", {traced(1, "ann", 3.5), traced(2, "bob", 3.2)});
  auto best = fastest(**db, "start S L L S L L", "");
  REQUIRE(best);
  CHECK(best->driver == "bob");
  CHECK(best->lap == doctest::Approx(3.2));
  CHECK(best->trace.find("3.2") != std::string::npos);
  // a slower lap keeps the best; a faster one replaces it; one driver's is found by name or car
  race(2, "start S L L S L L", {traced(1, "ann", 3.6), traced(2, "bob", 3.1)});
  CHECK(fastest(**db, "start S L L S L L", "ann")->lap == doctest::Approx(3.5));
  CHECK(fastest(**db, "start S L L S L L", "car1")->driver == "ann");
  CHECK(fastest(**db, "start S L L S L L", "")->lap == doctest::Approx(3.1));
  race(3, "start S L L S L L", {traced(1, "ann", 3.0)});
  CHECK(fastest(**db, "start S L L S L L", "")->driver == "ann");
  // another layout has bests of its own; an entry without a trace, or a race without a layout,
  // keeps none
  race(4, "start S S L L S S L L", {traced(1, "ann", 5.0), entry(2, "bob", 2, true, 1.0)});
  CHECK(fastest(**db, "start S S L L S S L L", "")->lap == doctest::Approx(5.0));
  CHECK_FALSE(fastest(**db, "start S S L L S S L L", "bob"));
  race(5, "", {traced(1, "ann", 0.5)});
  CHECK(fastest(**db, "start S L L S L L", "")->lap == doctest::Approx(3.0));
  CHECK_FALSE(fastest(**db, "start", ""));
  // a kept lap that is not whole (edited by hand, damaged) gives way to a slower new one
  sqlOn(t.path, "UPDATE best_laps SET trace = '{\"time\": 1' WHERE driver = 'bob'");
  race(6, "start S L L S L L", {traced(2, "bob", 3.9)});
  CHECK(fastest(**db, "start S L L S L L", "bob")->lap == doctest::Approx(3.9));
  sqlOn(t.path, "UPDATE best_laps SET lap = 0.5 WHERE driver = 'bob'");  // its time is 3.9
  race(7, "start S L L S L L", {traced(2, "bob", 4.0)});
  CHECK(fastest(**db, "start S L L S L L", "bob")->lap == doctest::Approx(4.0));
  // the fastest first, as many as asked for
  auto some = (*db)->bestLaps("start S L L S L L", "", 1);
  REQUIRE(some);
  CHECK(some->size() == 1);
  CHECK((*db)->bestLaps("start S L L S L L", "")->size() == 2);
}

TEST_CASE("standings: a database of schema 2 gains the personal bests, keeping its rows") {
  TempDb t;
  {
    auto db = Database::open(t.path);
    REQUIRE(db);
    auto event = (*db)->beginEvent({"race", "night", "oval", "{}"});
    REQUIRE((*db)->addRace(*event, {"race", 1, "oval", 3, {entry(1, "ann", 1, true, 3.0)}}));
  }
  sqlOn(t.path, "DROP TABLE best_laps; PRAGMA user_version = 2");
  auto db = Database::open(t.path);
  REQUIRE(db);
  CHECK((*db)->versionFound() == 2);
  CHECK((*db)->table({})->size() == 1);
  CHECK_FALSE(fastest(**db, "start S L L S L L", ""));
}

TEST_CASE(
    "standings: a race's best-lap trace survives the unsaved file's JSON, and a bad one is "
    "a sentence") {
  Race r{"race", 1, "oval", 3, {entry(1, "ann", 1, true, 3.0)}};
  r.layout = "start S L L S L L";
  r.entries[0].bestTrace = Entry::Trace{
      3.0, R"({"lap":2,"time":3,"length":100,"points":[[0,0,null,null],[3,100,400,0]]})"};
  auto back = raceFromJson(toJson(r));
  REQUIRE(back);
  CHECK(back->layout == r.layout);
  REQUIRE(back->entries[0].bestTrace);
  CHECK(back->entries[0].bestTrace->time == doctest::Approx(3.0));
  auto j = toJson(r);
  j["entries"][0]["bestTrace"]["points"] = {{0, 0, nullptr, nullptr}, {3, -5, 0, 0}};
  auto bad = raceFromJson(j);
  REQUIRE_FALSE(bad);
  CHECK(bad.error().find("race.entries[1].bestTrace: a kept lap's points go back") !=
        std::string::npos);
}
