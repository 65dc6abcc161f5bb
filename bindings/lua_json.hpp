#pragma once
// A Lua value as JSON (bindings/lua_json.cpp): tables with keys 1..n are arrays, others objects
// with string keys (numbers become their text); functions and other non-data are refused with
// where they are, as are tables nested or filled past the limits. What pitwall.view.race hands
// the view, and what a league heat hands its league (engine/cli/league_heat.cpp). The copy is
// counted by `budget` (bindings/copy_budget.hpp): it is made in C++, where neither the budget nor
// Ctrl-C can stop it.
#include <lua.hpp>

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "bindings/copy_budget.hpp"

namespace pitwall::lua {

struct JsonLimits {
  std::string what;  // who copies, for errors: "pitwall.view.race"
  std::string to;    // where the data goes, for errors: "the view"
  int maxDepth = 16;
  std::size_t maxEntries = 100000;  // values, all levels
  std::size_t valueBytes = 64;      // what a JSON value costs besides its text
};

// The value at idx; `where` names it in errors ("race").
nlohmann::json toJson(lua_State* L, int idx, const JsonLimits& limits, CopyBudget& budget,
                      const std::string& where);

}  // namespace pitwall::lua
