#include "bindings/world_copy.hpp"

#include "bindings/car_binding.hpp"
#include "bindings/car_lists.hpp"
#include "bindings/script_host.hpp"

namespace pitwall::lua {

bool WorldCopy::copy(int idx, const std::string& path, int depth) {
  idx = lua_absindex(from_, idx);
  switch (lua_type(from_, idx)) {
    case LUA_TNIL:
      lua_pushnil(to_);
      return true;
    case LUA_TBOOLEAN:
      lua_pushboolean(to_, lua_toboolean(from_, idx));
      return true;
    case LUA_TNUMBER:
      if (lua_isinteger(from_, idx))
        lua_pushinteger(to_, lua_tointeger(from_, idx));
      else
        lua_pushnumber(to_, lua_tonumber(from_, idx));
      return true;
    case LUA_TSTRING: {
      size_t n = 0;
      const char* s = lua_tolstring(from_, idx, &n);
      lua_pushlstring(to_, s, n);
      return true;
    }
    case LUA_TTABLE:
      return table(idx, path, depth);
    case LUA_TUSERDATA:
      if (AnkiCar* car = CarBinding::test(from_, idx)) {
        ScriptHost::from(to_).cars().push(to_, *car);
        return true;
      }
      break;
    default:
      break;
  }
  if (!quiet_) dropped_.push_back(path + " (a " + luaL_typename(from_, idx) + ")");
  return false;
}

bool WorldCopy::table(int idx, const std::string& path, int depth) {
  if (depth > 200 || !lua_checkstack(to_, 8) || !lua_checkstack(from_, 8)) {
    dropped_.push_back(path + " (nested too deep)");
    return false;
  }
  const void* key = lua_topointer(from_, idx);
  if (lua_rawgetp(to_, memo_, key) == LUA_TTABLE) return true;
  lua_pop(to_, 1);
  // Made at its size: filled key by key, an empty table is rehashed at 1, 2, 4, … entries.
  int array = 0, hash = 0;
  lua_pushnil(from_);
  while (lua_next(from_, idx)) {
    if (lua_isinteger(from_, -2) && lua_tointeger(from_, -2) == array + 1)
      ++array;
    else
      ++hash;
    lua_pop(from_, 1);
  }
  lua_createtable(to_, array, hash);
  lua_pushvalue(to_, -1);
  lua_rawsetp(to_, memo_, key);
  if (isCarList(from_, idx)) {
    makeCarList(to_, -1);  // a list of cars (pitwall.cars()) stays one
  } else if (lua_getmetatable(from_, idx)) {
    lua_pop(from_, 1);
    if (!quiet_) dropped_.push_back(path + "'s metatable");
  }
  lua_pushnil(from_);
  while (lua_next(from_, idx)) {  // raw traversal: no __pairs, no __index
    std::string keyPath = quiet_ ? path : path + keyText(-2);
    if (copy(-2, keyPath + " (as a key)", depth + 1)) {
      if (copy(-1, keyPath, depth + 1))
        lua_rawset(to_, -3);
      else
        lua_pop(to_, 1);
    }
    lua_pop(from_, 1);
  }
  return true;
}

// (Built with append: GCC 12's -Wrestrict misfires on "literal" + std::string in optimised
// builds.)
std::string WorldCopy::keyText(int idx) {
  std::string text;
  int type = lua_type(from_, idx);
  if (type == LUA_TSTRING) {
    text.append(".").append(lua_tostring(from_, idx));
  } else if (type == LUA_TNUMBER) {
    lua_pushvalue(from_, idx);  // tostring of a copy: lua_next needs the key unchanged
    text.append("[").append(lua_tostring(from_, -1)).append("]");
    lua_pop(from_, 1);
  } else {
    text.append("[").append(luaL_typename(from_, idx)).append("]");
  }
  return text;
}

}  // namespace pitwall::lua
