#pragma once
// Lists of cars that say which cars there are when a script reaches past them (docs/lua-api.md
// "Cars that are not there"). `cars[9]` and `cars.groundshok` are nil, as in any table — `if
// cars[9] then`, `ipairs(cars)` and `#cars` stay plain Lua —, but the error of using that nil,
// `cars[9]:setSpeed(500)`, names the cars there are instead of Lua's "attempt to index a nil
// value (field 'integer index')": `cars[9] is nil: there is no car 9; the cars are 1 groundshock,
// 2 skull, 3 thermo, 4 nuke`. The lists are the REPL's `cars` and every list pitwall.cars()
// returns. A list notes where a script's line asked it for a key it has not (its `__index`, which
// answers nil); the host's error handlers read that note after the fact, with raw reads only.
#include <lua.hpp>

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace pitwall::lua {

// Makes the table at `idx` such a list: a metatable of its own (a script that changes it changes
// no other list) whose __index answers nil and notes the miss.
void makeCarList(lua_State* L, int idx);
// The table at `idx` is such a list (the reloader carries the kind into a new version).
bool isCarList(lua_State* L, int idx);

// "the cars are 1 groundshock, 2 skull, 3 thermo, 4 nuke" (numbers and names; the first 8 and how
// many more), or "the run has no cars": the end of every sentence about a car that is not there.
std::string carsThereAre(const std::vector<std::pair<long long, std::string>>& cars);

// When `message` is Lua's error for indexing a nil (a field, local or upvalue) that a car list
// gave on the very line of `thread` that failed (the first Lua function from `level`), the message
// with that sentence instead; nullopt otherwise. Reads the list raw; runs nothing of the script.
std::optional<std::string> explainMissingCar(lua_State* thread, int level,
                                             const std::string& message);

}  // namespace pitwall::lua
