#pragma once
// The engine's metatables are locked (docs/safety.md, "No back door"): a script that reaches one
// through getmetatable or debug.getmetatable gets its public face instead — a table with copies of
// what the REPL and the editor's definitions read (__name, __methods, __fields, __events, the
// __index table of methods) — and cannot reach the metatable itself. Writing a new field to the
// face (`getmetatable(timer).__gc = f`) is refused with a sentence; `setmetatable` on it fails
// ("cannot change a protected metatable"). A finalizer planted on an engine type would run where
// Lua turns hooks off: neither the budget nor Ctrl-C could stop it.
//
// Every metatable the engine registers is locked with lockMetatable once its fields are set;
// tests/unit/bindings/sandbox_locks_test.cpp walks the registry and fails for one that is not.
#include <lua.hpp>

namespace pitwall::lua {

// Locks the metatable at `idx`: its __metatable becomes its public face. With `shareIndex` the
// face's __index is the metatable's own __index table rather than a copy (the string metatable:
// `getmetatable("").__index` is the `string` library, which scripts may extend). `what` names the
// type in the refusal ("cannot set __gc on the metatable of timer"); by default its __name.
void lockMetatable(lua_State* L, int idx, bool shareIndex = false, const char* what = nullptr);

// The metatable at `idx` is locked (its __metatable is set).
bool isLocked(lua_State* L, int idx);

}  // namespace pitwall::lua
