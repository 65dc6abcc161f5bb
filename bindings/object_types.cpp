#include "bindings/object_types.hpp"

namespace pitwall::lua {

void pushObjectTypes(lua_State* L) {
  lua_newtable(L);
  const int out = lua_gettop(L);
  lua_pushnil(L);
  while (lua_next(L, LUA_REGISTRYINDEX)) {
    // key at -2, value at -1
    if (lua_type(L, -2) == LUA_TSTRING && lua_istable(L, -1)) {
      const bool object = lua_getfield(L, -1, "__objecttype") != LUA_TNIL;
      lua_pop(L, 1);
      if (object) {
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
