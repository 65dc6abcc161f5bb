// A league's heats (engine/league/schedule.hpp) and its points and standings
// (engine/league/scoring.hpp): every pair meets, the same draw for the same seed, the tie rule.
#include "engine/league/schedule.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <map>
#include <set>
#include <utility>

#include "engine/league/scoring.hpp"

using namespace pitwall::league;

namespace {

// The pairs of drivers that raced together in the heats.
std::set<std::pair<int, int>> pairsMet(const std::vector<std::vector<int>>& heats) {
  std::set<std::pair<int, int>> met;
  for (const auto& h : heats)
    for (int a : h)
      for (int b : h)
        if (a < b) met.insert({a, b});
  return met;
}

}  // namespace

TEST_CASE("league: in every round every pair of drivers meets, in full heats of distinct drivers") {
  for (int drivers = 2; drivers <= 24; ++drivers)
    for (int perHeat = 2; perHeat <= 6; ++perHeat)
      for (int rounds = 1; rounds <= 2; ++rounds) {
        CAPTURE(drivers);
        CAPTURE(perHeat);
        CAPTURE(rounds);
        const auto heats = drawHeats(drivers, perHeat, rounds, 7);
        REQUIRE_FALSE(heats.empty());
        for (const auto& h : heats) {
          CHECK(h.size() == static_cast<std::size_t>(std::min(drivers, perHeat)));
          CHECK(std::set<int>(h.begin(), h.end()).size() == h.size());
          for (int d : h) CHECK((d >= 0 && d < drivers));
        }
        CHECK(pairsMet(heats).size() == static_cast<std::size_t>(drivers * (drivers - 1) / 2));
        // each round covers every pair: with two rounds every pair met at least twice
        std::map<std::pair<int, int>, int> meetings;
        for (const auto& h : heats)
          for (int a : h)
            for (int b : h)
              if (a < b) ++meetings[{a, b}];
        int fewest = rounds + 1;
        for (const auto& [pair, count] : meetings) fewest = std::min(fewest, count);
        CHECK(fewest >= rounds);
      }
}

TEST_CASE("league: the draw is the same for a seed, and another seed draws other heats") {
  CHECK(drawHeats(12, 4, 2, 1) == drawHeats(12, 4, 2, 1));
  bool differs = false;
  for (std::uint64_t seed = 2; seed < 12 && !differs; ++seed)
    differs = drawHeats(12, 4, 1, 1) != drawHeats(12, 4, 1, seed);
  CHECK(differs);
}

TEST_CASE("league: the draw is not wasteful: 8 drivers in heats of 4 need at most 6 heats") {
  // 28 pairs, 6 a heat: at least 5 heats; the greedy draw stays close
  CHECK(drawHeats(8, 4, 1, 1).size() <= 6);
  CHECK(drawHeats(4, 4, 1, 1).size() == 1);
  CHECK(drawHeats(3, 4, 1, 1) == std::vector<std::vector<int>>{{0, 1, 2}});
}

TEST_CASE("league: a shard runs every Nth heat, and the shards together run each heat once") {
  for (std::size_t heat = 0; heat < 20; ++heat) {
    int owners = 0;
    for (int shard = 1; shard <= 3; ++shard) owners += inShard(heat, shard, 3);
    CHECK(owners == 1);
  }
  CHECK(inShard(5, 1, 1));
}

TEST_CASE("league: points per place, none for a driver that did not finish") {
  CHECK(pointsFor(1, true) == 25);
  CHECK(pointsFor(2, true) == 18);
  CHECK(pointsFor(10, true) == 1);
  CHECK(pointsFor(11, true) == 0);
  CHECK(pointsFor(1, false) == 0);
  CHECK(pointsFor(0, true) == 0);
}

TEST_CASE("league: standings: points, then count-back, then qualifying, then race lap, then name") {
  // heat 1: 0 wins, 1 second; heat 2: 1 wins, 0 second — equal points, equal places
  std::vector<std::vector<Place>> heats = {
      {{0, 1, true, 4.0}, {1, 2, true, 4.1}, {2, 3, false, std::nullopt}},
      {{1, 1, true, 4.2}, {0, 2, true, 4.3}, {2, 3, true, 5.0}}};
  auto table = standings(3, heats, {4.5, 4.4, std::nullopt});
  REQUIRE(table.size() == 3);
  CHECK(table[0].driver == 1);  // 43 points each: qualifying 4.4 beats 4.5
  CHECK(table[0].points == 43);
  CHECK(table[1].driver == 0);
  CHECK(table[2].driver == 2);
  CHECK(table[2].points == 15);  // a DNF scores nothing; its third place in heat 2 does
  CHECK(table[2].finishes == 1);
  CHECK(*table[0].bestLap == doctest::Approx(4.1));
  // count-back before qualifying: a win beats two seconds' worth of the same points? no: the
  // same points, and the one with more wins is ahead whatever the qualifying
  std::vector<std::vector<Place>> countBack = {{{0, 1, true, {}}, {1, 2, true, {}}},
                                               {{1, 1, true, {}}, {0, 2, true, {}}},
                                               {{1, 3, true, {}}, {0, 4, true, {}}}};
  // 0: 25+18+12 = 55, places 1,2,4; 1: 18+25+15 = 58
  auto t2 = standings(2, countBack, {3.0, 9.0});
  CHECK(t2[0].driver == 1);
  // equal everything: a time before no time, then the index
  auto t3 = standings(3, {}, {std::nullopt, 5.0, std::nullopt});
  CHECK(t3[0].driver == 1);
  CHECK(t3[1].driver == 0);
  CHECK(t3[2].driver == 2);
}

TEST_CASE("league: a heat's grid is its drivers by qualifying lap, fastest first") {
  CHECK(gridOrder({3, 1, 2}, {9.0, 4.2, std::nullopt, 4.1}) == std::vector<int>{3, 1, 2});
  CHECK(gridOrder({2, 0}, {std::nullopt, 1.0, std::nullopt}) == std::vector<int>{2, 0});
}
