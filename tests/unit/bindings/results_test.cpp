// Results files (engine/record/results.hpp) and pitwall.writeResults.
#include "engine/record/results.hpp"

#include <doctest/doctest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bindings/script_host.hpp"
#include "engine/fleet/fleet.hpp"

using namespace pitwall;
using results::Cell;

namespace {
results::Table sample() {
  results::Table t;
  t.columns = {"position", "car", "laps", "bestLap", "finished"};
  t.rows.push_back({Cell{1.0}, Cell{std::string("skull")}, Cell{10.0}, Cell{4.125}, Cell{true}});
  t.rows.push_back(
      {Cell{2.0}, Cell{std::string("say \"hi\", then go")}, Cell{9.0}, Cell{}, Cell{false}});
  return t;
}
std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}
}  // namespace

TEST_CASE("results: the format comes from the extension, and a wrong one is named") {
  CHECK(*results::formatOf("race.json") == results::Format::Json);
  CHECK(*results::formatOf("RACE.CSV") == results::Format::Csv);
  auto bad = results::formatOf("race.txt");
  REQUIRE_FALSE(bad);
  CHECK(bad.error() == "results file 'race.txt' must end in .json or .csv (that picks the format)");
}

TEST_CASE("results: JSON is an array of objects in column order, null for nothing") {
  auto text = results::render(sample(), results::Format::Json);
  auto j = nlohmann::ordered_json::parse(text);
  REQUIRE(j.size() == 2);
  CHECK(j[0].dump() == R"({"position":1,"car":"skull","laps":10,"bestLap":4.125,"finished":true})");
  CHECK(j[1]["finished"] == false);
  CHECK(j[1]["bestLap"].is_null());
  CHECK(j[1]["car"] == "say \"hi\", then go");
}

TEST_CASE("results: CSV has a header and quotes what needs quoting") {
  CHECK(results::render(sample(), results::Format::Csv) ==
        "position,car,laps,bestLap,finished\n"
        "1,skull,10,4.125,true\n"
        "2,\"say \"\"hi\"\", then go\",9,,false\n");
}

TEST_CASE("results: times are written to the millisecond, in JSON and in CSV") {
  results::Table t;
  t.columns = {"totalTime", "bestLap", "gap", "laps"};
  t.rows.push_back({Cell{1234.56789}, Cell{62.3454999}, Cell{-0.0004}, Cell{10.0}});
  t.rows.push_back({Cell{59.9996}, Cell{0.1 + 0.2}, Cell{1e20}, Cell{2.5}});
  auto j = nlohmann::ordered_json::parse(results::render(t, results::Format::Json));
  CHECK(j[0].dump() == R"({"totalTime":1234.568,"bestLap":62.345,"gap":0,"laps":10})");
  CHECK(j[1].dump() == R"({"totalTime":60,"bestLap":0.3,"gap":1e+20,"laps":2.5})");
  CHECK(results::render(t, results::Format::Csv) ==
        "totalTime,bestLap,gap,laps\n"
        "1234.568,62.345,0,10\n"
        "60,0.3,1e+20,2.5\n");
}

TEST_CASE("results: a folder that does not exist is refused before anything is written") {
  auto w = results::writable("/nonexistent-pitwall-dir/race.json");
  REQUIRE_FALSE(w);
  CHECK(w.error().find("cannot write results to '/nonexistent-pitwall-dir/race.json'") == 0);
}

TEST_CASE("pitwall.writeResults writes the rows to --results, and refuses what it cannot write") {
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  std::string path = "/tmp/pitwall-results-test-" + std::to_string(::getpid()) + ".csv";
  HostOptions options;
  options.results = path;
  setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
  ScriptHost host(loop, fleet, nullptr, options);
  lua_State* L = host.state();
  REQUIRE(luaL_dostring(L, "return pitwall.resultsFile") == LUA_OK);
  CHECK(std::string(lua_tostring(L, -1)) == path);
  REQUIRE(luaL_dostring(L,
                        "return pitwall.writeResults({{position = 1, car = 'skull', laps = 3, "
                        "fast = true}}, {'position', 'car', 'laps', 'fast', 'missing'})") ==
          LUA_OK);
  CHECK(std::string(lua_tostring(L, -1)) == path);
  CHECK(slurp(path) == "position,car,laps,fast,missing\n1,skull,3,true,\n");
  std::remove(path.c_str());
  CHECK(luaL_dostring(L, "pitwall.writeResults({{car = {}}}, {'car'})") != LUA_OK);
  CHECK(std::string(lua_tostring(L, -1)).find("row 1, car: a table cannot go in a results file") !=
        std::string::npos);
  CHECK(luaL_dostring(L, "pitwall.writeResults({}, {'car'}, 'race.txt')") != LUA_OK);
  CHECK(std::string(lua_tostring(L, -1)).find("must end in .json or .csv") != std::string::npos);
}
