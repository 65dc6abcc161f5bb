#include "bindings/lua_json.hpp"

#include <cmath>

#include "bindings/lua_args.hpp"
#include "engine/core/printable.hpp"

namespace pitwall::lua {

namespace {

nlohmann::json toJson(lua_State* L, int idx, const JsonLimits& limits, int depth,
                      std::size_t& count, CopyBudget& budget, const std::string& where) {
  budget.add(limits.valueBytes, where);
  if (++count > limits.maxEntries)
    throw LuaError(limits.what + ": the table holds more than " +
                   std::to_string(limits.maxEntries) + " values");
  switch (lua_type(L, idx)) {
    case LUA_TNIL:
      return nullptr;
    case LUA_TBOOLEAN:
      return lua_toboolean(L, idx) != 0;
    case LUA_TNUMBER:
      if (lua_isinteger(L, idx)) return static_cast<long long>(lua_tointeger(L, idx));
      {
        double d = lua_tonumber(L, idx);
        return std::isfinite(d) ? nlohmann::json(d) : nlohmann::json(nullptr);
      }
    case LUA_TSTRING: {
      std::size_t n = 0;
      const char* s = lua_tolstring(L, idx, &n);
      budget.add(n, where);
      return std::string(s, n);  // invalid UTF-8 is replaced when the feed is written
    }
    case LUA_TTABLE:
      break;
    default:
      throw LuaError(limits.what + ": " + where + " is a " + luaL_typename(L, idx) +
                     "; only data (tables, strings, numbers, booleans) goes to " + limits.to);
  }
  if (depth >= limits.maxDepth)
    throw LuaError(limits.what + ": " + where + " is nested deeper than " +
                   std::to_string(limits.maxDepth) + " tables");
  idx = lua_absindex(L, idx);
  luaL_checkstack(L, 4, limits.what.c_str());
  const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L, idx));
  std::size_t keys = 0;
  lua_pushnil(L);
  while (lua_next(L, idx)) {
    if (count + ++keys > limits.maxEntries)  // before the copy: counting a huge table is work too
      throw LuaError(limits.what + ": the table holds more than " +
                     std::to_string(limits.maxEntries) + " values");
    lua_pop(L, 1);
  }
  if (keys == static_cast<std::size_t>(n)) {  // an empty table is an empty list
    nlohmann::json a = nlohmann::json::array();
    for (lua_Integer i = 1; i <= n; ++i) {
      lua_rawgeti(L, idx, i);
      a.push_back(
          toJson(L, -1, limits, depth + 1, count, budget, where + "[" + std::to_string(i) + "]"));
      lua_pop(L, 1);
    }
    return a;
  }
  nlohmann::json o = nlohmann::json::object();
  lua_pushnil(L);
  while (lua_next(L, idx)) {
    std::string key;
    if (lua_type(L, -2) == LUA_TSTRING) {
      key = lua_tostring(L, -2);
    } else if (lua_type(L, -2) == LUA_TNUMBER) {
      lua_pushvalue(L, -2);
      key = lua_tostring(L, -1);
      lua_pop(L, 1);
    } else {
      throw LuaError(limits.what + ": " + where + " has a " + luaL_typename(L, -2) +
                     " key; keys are strings or numbers");
    }
    // the path names at most 40 bytes of a key: a 1 MiB key over 100 000 values would otherwise
    // be copied into the path of each of them (work no budget counts)
    const std::string path = where + "." + printable(key, 40);
    budget.add(key.size(), path);
    o[key] = toJson(L, -1, limits, depth + 1, count, budget, path);
    lua_pop(L, 1);
  }
  return o;
}

}  // namespace

nlohmann::json toJson(lua_State* L, int idx, const JsonLimits& limits, CopyBudget& budget,
                      const std::string& where) {
  std::size_t count = 0;
  return toJson(L, idx, limits, 0, count, budget, where);
}

}  // namespace pitwall::lua
