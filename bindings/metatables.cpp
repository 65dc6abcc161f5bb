#include "bindings/metatables.hpp"

#include <cstring>
#include <initializer_list>

namespace pitwall::lua {

namespace {

// __newindex of a face: (face, key, value). Every key a face has was set when it was made, so
// this runs for every new one, __gc included.
// Upvalue 1: how the message names the type.
int refuseWrite(lua_State* L) {
  const char* type = lua_tostring(L, lua_upvalueindex(1));
  const char* key = luaL_tolstring(L, 2, nullptr);
  return luaL_error(L,
                    "cannot set %s on the metatable of %s: the engine's metatables are locked (a "
                    "finalizer or a metamethod planted there would run where the budget and Ctrl-C "
                    "cannot stop it); keep your own fields on your own tables (docs/safety.md)",
                    key, type);
}

// A shallow copy of the table at `idx`, pushed.
void pushCopy(lua_State* L, int idx) {
  idx = lua_absindex(L, idx);
  lua_newtable(L);
  lua_pushnil(L);
  while (lua_next(L, idx)) {
    lua_pushvalue(L, -2);
    lua_insert(L, -2);
    lua_rawset(L, -4);
  }
}

}  // namespace

void lockMetatable(lua_State* L, int idx, bool shareIndex, const char* what) {
  idx = lua_absindex(L, idx);
  if (!what) {
    lua_getfield(L, idx, "__name");
    lua_pushstring(L, lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "an engine type");
    lua_remove(L, -2);
  } else {
    lua_pushstring(L, what);
  }
  const int name = lua_gettop(L);
  lua_newtable(L);  // the face
  for (const char* key : {"__name", "__methods", "__fields", "__events", "__index"}) {
    const int type = lua_getfield(L, idx, key);  // raw enough: a metatable has no metatable
    if (type == LUA_TSTRING ||
        (type == LUA_TTABLE && shareIndex && std::strcmp(key, "__index") == 0)) {
      lua_setfield(L, -2, key);
    } else if (type == LUA_TTABLE) {
      pushCopy(L, -1);
      lua_setfield(L, -3, key);
      lua_pop(L, 1);
    } else {
      lua_pop(L, 1);
    }
  }
  lua_createtable(L, 0, 2);  // the face's own metatable: no new field, no other metatable
  lua_pushvalue(L, name);
  lua_pushcclosure(L, refuseWrite, 1);
  lua_setfield(L, -2, "__newindex");
  lua_pushliteral(L, "locked");
  lua_setfield(L, -2, "__metatable");
  lua_setmetatable(L, -2);
  lua_setfield(L, idx, "__metatable");
  lua_pop(L, 1);  // the name
}

bool isLocked(lua_State* L, int idx) {
  idx = lua_absindex(L, idx);
  lua_pushliteral(L, "__metatable");
  const bool locked = lua_rawget(L, idx) != LUA_TNIL;
  lua_pop(L, 1);
  return locked;
}

}  // namespace pitwall::lua
