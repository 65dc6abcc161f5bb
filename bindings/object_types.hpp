#pragma once
// The metatables of a Lua world's object types, as the binding registered them: what the LuaLS
// definitions are generated from (scripts/pitwall/types.lua, `pitwall types`, docs/editor.md).
#include <lua.hpp>

namespace pitwall::lua {

// Pushes a table: registry key → metatable (its locked public face, bindings/metatables.hpp),
// for every type registered through lua::registerType (its __methods, __fields, __events). Scripts
// reach a metatable only through an object; the generator must see every type, robots included,
// without making one.
void pushObjectTypes(lua_State* L);

}  // namespace pitwall::lua
