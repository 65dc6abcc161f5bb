#pragma once
// A misspelled method, `car:setSped(300)`: Lua itself says "attempt to call a nil value (method
// 'setSped')". The host's error handlers (lua::traceback, a task's error) rewrite that sentence
// to "car has no method setSped; did you mean setSpeed?" — after the fact, from the stack of the
// call that failed, so that reading a field (`if car.someOwnField then`) stays plain Lua: nothing
// answers a missing name with anything but nil (docs/lua-api.md "Misspelled methods"). A
// misspelled library function, `pitwall.spwan(f)`, is told the same way ("Misspelled library
// functions").
#include <lua.hpp>

#include <optional>
#include <string>

namespace pitwall::lua {

// When `message` is Lua's error for calling a missing method, the same message with that
// sentence replaced, naming the object's type and the nearest method. The object is found on
// the stack of `thread` at `level` (the function whose call failed): the method's register is a
// nil temporary, the object the one after it. Types: those with a `__methods` table in their
// metatable (cars, robots) and Lua classes (a metatable with `__name` and an `__index` table:
// the race, the board, …). nullopt when it is no such error, or no such object is found.
std::optional<std::string> explainMissingMethod(lua_State* thread, int level,
                                                const std::string& message);

// When `message` is Lua's error for calling a missing field, `pitwall.spwan(f)` ("attempt to call
// a nil value (field 'spwan')"), and a library table the failing function can see — the pitwall
// table, a library module (`require "pitwall.race"`), pitwall.sim, pitwall.view —, lacks that
// name but has a function near it: "pitwall has no function spwan; did you mean pitwall.spawn?".
// The table is named as the function sees it (a local `race`, the global `pitwall`). Lua's
// message does not say which table it was: a script's own table with a name missing near a
// library function's would be taken for that library, which is why only near names count.
std::optional<std::string> explainMissingFunction(lua_State* thread, int level,
                                                  const std::string& message);

// The host's explainers in turn: a missing method, a missing library function, a car a list of
// cars has not (bindings/car_lists.hpp). What the error handlers call.
std::optional<std::string> explainMissingName(lua_State* thread, int level,
                                              const std::string& message);

}  // namespace pitwall::lua
