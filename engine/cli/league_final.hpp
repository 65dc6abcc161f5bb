#pragma once
// pitwall run --league-final DB[:EVENT] (docs/league.md "The final"): the top drivers of a league
// kept in the standings database race on this run's cars — real ones with --ble — with the same
// driver files and rules, the grid in the order of the league's standings.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "engine/core/result.hpp"

namespace pitwall::cli {

struct FinalPlan {
  std::string db;  // the league's database: the final is kept there
  std::int64_t league = 0;
  std::string title;                 // "Final: <the league's title>"
  int laps = 5;                      // the league's heats'
  std::vector<std::string> drivers;  // pole first
  std::map<int, std::string> files;  // car number → driver file
  std::string script;                // the shipped final (scripts/pitwall/league_final.lua)
};

// `given`: DB or DB:EVENT (the league's id, as `pitwall standings --events` lists it; default the
// last league that ended); `cars`: how many race (0: as many as the league's heats had). Refused
// with a sentence: no such file or league, a driver's file that is gone.
Result<FinalPlan, std::string> planFinal(const std::string& given, int cars);

}  // namespace pitwall::cli
