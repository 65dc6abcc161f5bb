#include "bindings/object_types.hpp"

#include <cstring>

namespace pitwall::lua {

namespace {
constexpr const char* kTimerMetatable = "pitwall.timer";  // bindings/pitwall_module.cpp
constexpr const char* kSeatMetatable = "pitwall.seat";    // bindings/seat_binding.cpp
}  // namespace

void pushObjectTypes(lua_State* L) {
  lua_newtable(L);
  const int out = lua_gettop(L);
  lua_pushnil(L);
  while (lua_next(L, LUA_REGISTRYINDEX)) {
    // key at -2, value at -1
    if (lua_type(L, -2) == LUA_TSTRING && lua_istable(L, -1)) {
      const bool object = lua_getfield(L, -1, "__objecttype") != LUA_TNIL;
      lua_pop(L, 1);
      const char* key = lua_tostring(L, -2);
      if (object || std::strcmp(key, kTimerMetatable) == 0 ||
          std::strcmp(key, kSeatMetatable) == 0) {
        // Its public face (bindings/metatables.hpp): what getmetatable gives a script, with the
        // same names; the metatable itself is not handed to Lua code.
        lua_pushvalue(L, -2);
        lua_pushliteral(L, "__metatable");
        if (lua_rawget(L, -3) != LUA_TTABLE) {
          lua_pop(L, 1);
          lua_pushvalue(L, -2);
        }
        lua_rawset(L, out);
      }
    }
    lua_pop(L, 1);
  }
}

}  // namespace pitwall::lua
