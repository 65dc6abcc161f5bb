// The view's lap comparison (engine/view/lap_compare.cpp, docs/view.md "Comparing two laps"):
// two laps the feed traced compared as `pitwall compare` does; a query that is not two of them
// gets a sentence, whatever it holds.
#include "engine/view/lap_compare.hpp"

#include <doctest/doctest.h>

#include "engine/fleet/fleet.hpp"
#include "engine/sim/world.hpp"
#include "tests/support/sim_cars.hpp"

using namespace pitwall;

TEST_CASE("view lap comparison: two traced laps compared, anything else a sentence") {
  Loop loop{ClockKind::Virtual};
  sim::World world(loop, sim::namedLayout("oval").value(), 1);
  Fleet fleet{loop};
  view::Feed feed{loop, fleet, "simulator"};
  CHECK_FALSE(view::compareLaps(feed, "a=1:1&b=1:2"));  // no track yet
  feed.setTrack(world.track(), "layout");
  auto& car = testing::addSimulatedCar(loop, fleet, world, sim::CarSpec{.name = "skull"});
  loop.at(loop.now() + fromSeconds(0.5), [&] { loop.stop(); });
  loop.run();
  REQUIRE(car.sdkMode(true));
  REQUIRE(car.setSpeed(900, 20000));
  loop.at(loop.now() + fromSeconds(20), [&] { loop.stop(); });
  loop.run();

  const auto list = view::lapList(feed);
  REQUIRE(list["cars"].size() == 1);
  CHECK(list["cars"][0]["name"] == "skull");
  REQUIRE(list["cars"][0]["laps"].size() >= 3);

  for (const char* query : {"a=1:1&b=1:2", "b=1:2&a=1:1", "a=1%3A1&b=1%3a2"}) {
    CAPTURE(query);
    auto c = view::compareLaps(feed, query);
    REQUIRE(c);
    CHECK((*c)["laps"].size() == 2);
    CHECK((*c)["laps"][0]["label"] == "car 1 (skull) lap 1");
    CHECK((*c)["sections"].size() == 5);
    CHECK((*c)["svg"].get<std::string>().find("class=\"delta\"") != std::string::npos);
  }
  const std::string huge(1 << 20, '9');
  for (const std::string& query :
       {std::string(""), std::string("a=1:1"), std::string("a=x:1&b=1:1"),
        std::string("a=-1:1&b=1:1"), std::string("a=1:0&b=1:1"), std::string("a=1:&b=1:1"),
        std::string("a=:1&b=1:1"), std::string("a=1:1:1&b=1:1"), std::string("a=1:1\0&b=1:1", 12),
        "a=" + huge + ":1&b=1:1", std::string("a=1:1e3&b=1:1"), std::string("a=1 :1&b=1:1")}) {
    CAPTURE(query.substr(0, 40));
    auto c = view::compareLaps(feed, query);
    REQUIRE_FALSE(c);
    CHECK(c.error() == "give two laps as ?a=CAR:LAP&b=CAR:LAP (numbers, e.g. a=1:3&b=2:3)");
  }
  auto missing = view::compareLaps(feed, "a=1:1&b=1:999");
  REQUIRE_FALSE(missing);
  CHECK(missing.error() == "car 1 has no traced lap 999 (GET /api/laps lists the laps there are)");
  CHECK_FALSE(view::compareLaps(feed, "a=7:1&b=1:1"));
}
