// pitwall.view (bindings/view_binding.cpp) and the race library's reports to the race view
// (scripts/pitwall/race_view.lua): hostile tables refused with where they are, and a real race
// in virtual time whose phases, table and laps reach the feed — laps the same as the feed's own.
#include <doctest/doctest.h>

#include <algorithm>

#include "bindings/sandbox.hpp"
#include "bindings/script_host.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/sim/grid.hpp"
#include "engine/view/feed.hpp"
#include "tests/support/sim_cars.hpp"

using namespace pitwall;

namespace {

std::string error(lua_State* L, const std::string& code) {
  if (luaL_dostring(L, code.c_str()) == LUA_OK) return "";
  std::string e = lua_tostring(L, -1) ? lua_tostring(L, -1) : "?";
  lua_pop(L, 1);
  return e;
}

}  // namespace

TEST_CASE("pitwall.view: data goes to the view; anything else is refused with where it is") {
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  view::Feed feed(loop, fleet, "simulator");
  HostOptions options;
  options.view = &feed;
  ScriptHost host(loop, fleet, nullptr, options);
  lua_State* L = host.state();
  CHECK(error(L, "assert(pitwall.view.active)") == "");
  CHECK(error(L,
              "pitwall.view.race{title = 'GP', phase = 'grid', rows = {{car = 'a', lap = 1}},"
              " lapTimes = {['3'] = {4.5, 4.25}}, nan = 0/0, inf = math.huge, empty = {},"
              " bad = 'caf\\xff\\xfe'}") == "");
  auto race = feed.state()["race"];
  CHECK(race["title"] == "GP");
  CHECK(race["rows"][0]["car"] == "a");
  CHECK(race["lapTimes"]["3"][1] == 4.25);
  CHECK(race["nan"].is_null());
  CHECK(race["inf"].is_null());
  CHECK(race["empty"].is_array());
  // invalid UTF-8 reaches a browser replaced, never as a broken feed
  CHECK(feed.state().dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).find("caf") !=
        std::string::npos);

  CHECK(error(L, "pitwall.view.race{rows = {{car = print}}}")
            .find("race.rows[1].car is a function") != std::string::npos);
  CHECK(error(L, "local t = {} t.self = t pitwall.view.race(t)").find("nested deeper than 16") !=
        std::string::npos);
  CHECK(error(L, "local t = {} for i = 1, 200000 do t[i] = i end pitwall.view.race(t)")
            .find("more than 100000 values") != std::string::npos);
  CHECK(error(L, "pitwall.view.race{[{}] = 1}").find("has a table key") != std::string::npos);
  CHECK(error(L, "pitwall.view.race(42)") != "");
  CHECK(error(L, "pitwall.view.event('hello', 'loud')")
            .find("level 'loud' is unknown (use info, warn or error)") != std::string::npos);
  // a refused table leaves the last good one
  CHECK(feed.state()["race"]["title"] == "GP");
  CHECK(error(L, "pitwall.view.race(nil)") == "");
  CHECK(feed.state()["race"].is_null());

  CHECK(error(L, "pitwall.view.event(string.rep('x', 5000), 'warn')") == "");
  auto events = feed.state()["events"];
  CHECK(events.back()["level"] == "warn");
  CHECK(events.back()["text"].get<std::string>().size() == 1000);

  // a scanned map is drawn (ids, turns), starting with the start piece like a layout
  CHECK(error(L,
              "pitwall.view.track{pieces = {{id = 33}, {id = 36}, {id = 17, turn = 'left'},"
              " {id = 18, turn = 'left'}, {id = 39}, {id = 40}, {id = 20, turn = 'left'},"
              " {id = 23, turn = 'left'}, {id = 34}}}") == "");
  REQUIRE(feed.track());
  CHECK(feed.track()->pieces().front().id == 34);
  CHECK(feed.track()->pieces()[3].turn == 1);
  CHECK(feed.state()["track"]["source"] == "scan");
  CHECK(error(L, "pitwall.view.track{pieces = {{id = 300}}}").find("not 300") != std::string::npos);
  CHECK(error(L, "pitwall.view.track{pieces = {{id = 'x'}}}").find("piece 1 needs an id") !=
        std::string::npos);
  CHECK(error(L, "pitwall.view.track{pieces = {{id = 3.5}}}").find("piece 1 needs an id") !=
        std::string::npos);
  // a metamethod of the script's is never run inside (raw reads): no "boom", the id is missing
  CHECK(error(L,
              "pitwall.view.track{pieces = {setmetatable({}, {__index = function() "
              "error('boom') end})}}")
            .find("piece 1 needs an id") != std::string::npos);
  CHECK(error(L, "pitwall.view.race{title = 5, phase = 'grid'}") == "");  // odd, but data
  CHECK(feed.state()["events"].back()["text"] == "race: grid");
}

// Issue 33: with --lua-memory 64, one 1 MiB string referenced 1500 times in the table took the
// process to 1.55 GB and held the loop ~8 s. The copy is bounded (8 MiB) and counted against the
// world's memory cap; a refusal says which limit and leaves the last good table.
TEST_CASE("pitwall.view.race: a copy past its size or the memory cap is refused with a sentence") {
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  view::Feed feed(loop, fleet, "simulator");
  HostOptions options;
  options.view = &feed;
  options.memory_limit = std::size_t{64} << 20;
  ScriptHost host(loop, fleet, nullptr, options);
  lua_State* L = host.state();
  CHECK(error(L, "pitwall.view.race{title = 'before'}") == "");

  const std::string refused = error(L, R"(
    local big = string.rep("x", 1 << 20)
    local rows = {}
    for i = 1, 1500 do rows[i] = {car = big} end
    pitwall.view.race{rows = rows})");
  CHECK_MESSAGE(refused.find("pitwall.view.race: the data is more than 8 MiB") != std::string::npos,
                refused);
  CHECK(refused.find("race.rows[") != std::string::npos);  // where it passed the limit
  CHECK(refused.find("counts at every place it is used") != std::string::npos);
  CHECK(feed.state()["race"]["title"] == "before");

  // Under its own limit but past what the cap leaves: 60 MiB held, 5 MiB to copy.
  const std::string capped = error(L, R"(
    hold = {}
    for i = 1, 60 do hold[i] = string.rep(string.char(64 + i % 26), 1 << 20) end
    local rows = {}
    for i = 1, 5 do rows[i] = hold[i] end
    pitwall.view.race{rows = rows})");
  CHECK_MESSAGE(
      capped.find("that the script's memory limit of 64 MB still leaves") != std::string::npos,
      capped);
  CHECK(capped.find("raise --lua-memory") != std::string::npos);
  CHECK(feed.state()["race"]["title"] == "before");

  // What the feed keeps is charged to the world until the next table replaces it.
  CHECK(error(L, "hold = nil collectgarbage() collectgarbage()") == "");
  CHECK(error(L, "pitwall.view.race{rows = {string.rep('y', 3 << 20)}}") == "");
  CHECK(host.memory().outside > (std::size_t{3} << 20));
  CHECK(error(L, "pitwall.view.race{title = 'after'}") == "");
  CHECK(host.memory().outside < 1024);
  CHECK(feed.state()["race"]["title"] == "after");
}

TEST_CASE("pitwall.view without a view: nothing happens, nothing fails") {
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  ScriptHost host(loop, fleet, nullptr, HostOptions{});
  lua_State* L = host.state();
  CHECK(error(L,
              "assert(pitwall.view.active == false) pitwall.view.race{a = 1}"
              " pitwall.view.event('x')") == "");
}

TEST_CASE("race library → view: phases in order, the table with drivers, the same laps") {
  setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
  Loop loop{ClockKind::Virtual};
  SimSession sim;
  sim.world = std::make_unique<sim::World>(loop, *sim::loadLayout("oval"), 1);
  Fleet fleet{loop};
  for (int i = 0; i < 3; ++i)
    testing::addSimulatedCar(loop, fleet, *sim.world, sim::gridSpec(sim.world->track(), i));
  auto until = loop.after(std::chrono::seconds(1), [&] { loop.stop(); });
  loop.run();
  loop.cancel(until);
  view::Feed feed(loop, fleet, "simulator");
  feed.setTrack(sim.world->track(), "layout");
  HostOptions options;
  options.view = &feed;
  ScriptHost host(loop, fleet, &sim, options);
  std::vector<std::string> phases;
  nlohmann::json last;
  int maxLight = 0;         // the most lights seen on (the phone's countdown reads them)
  nlohmann::json lightsOf;  // the lights' count and the jump start's penalty, as in the lights
  std::function<void()> watch = [&] {
    auto race = feed.state()["race"];
    if (race.is_object()) {
      std::string phase = race["phase"];
      if (phases.empty() || phases.back() != phase) phases.push_back(phase);
      if (phase == "lights") {
        maxLight = std::max(maxLight, race.value("light", 0));
        lightsOf = {{"lights", race.value("lights", 0)}, {"penalty", race.value("penalty", 0.0)}};
      }
      last = race;
    }
    loop.after(std::chrono::milliseconds(50), watch);
  };
  loop.after(std::chrono::milliseconds(50), watch);
  auto started = host.startString(R"(
    local race = require "pitwall.race"
    local drivers = require "pitwall.drivers"
    local names = {"cruiser", "lanekeeper", "follower"}
    race.laps{laps = 3, title = "Test GP",
      drivers = function(car, i) return drivers.load(names[i]).new{speed = 900 + 50 * i} end}
    pitwall.sleep(0.5)
    pitwall.stop()
  )",
                                  "gp");
  REQUIRE(started);
  host.onStopRequested = [&] { loop.stop(); };
  auto cap = loop.after(std::chrono::seconds(300), [&] { loop.stop(); });
  loop.run();
  loop.cancel(cap);
  CHECK(host.errorCount() == 0);
  std::vector<std::string> expected{"grid", "lights", "racing", "ending", "done"};
  std::string got;
  for (const auto& p : phases) got += p + " ";
  CAPTURE(got);
  CHECK(phases == expected);
  CHECK(maxLight == 5);
  CHECK(lightsOf == nlohmann::json{{"lights", 5}, {"penalty", 5.0}});
  CHECK(last["penalty"] == 5);
  REQUIRE(last["rows"].size() == 3);
  std::vector<std::string> seen;
  for (const auto& row : last["rows"]) {
    seen.push_back(row["driver"]);
    CHECK(row["finished"] == true);
    CHECK(row["laps"] == 3);
    // the race library's laps are the last laps the feed counted (the drive to the grid
    // crossed the line before them), to the millisecond
    const auto* tracker = feed.tracker(row["number"].get<int>());
    REQUIRE(tracker);
    auto mine = last["lapTimes"][std::to_string(row["number"].get<int>())];
    REQUIRE(mine.size() == 3);
    REQUIRE(tracker->lapTimes().size() >= 3);
    for (std::size_t k = 0; k < 3; ++k)
      CHECK(
          mine[k].get<double>() ==
          doctest::Approx(tracker->lapTimes()[tracker->lapTimes().size() - 3 + k]).epsilon(0.001));
  }
  std::sort(seen.begin(), seen.end());
  CHECK(seen == std::vector<std::string>{"cruiser", "follower", "lanekeeper"});
  CHECK(last["title"] == "Test GP");
  CHECK(last["status"].is_string());
}
