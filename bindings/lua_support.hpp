#pragma once
// Small tools every binding uses. Lua raises errors with longjmp, which must never cross a C++
// frame holding live objects (LÖVE's rule): binding bodies throw LuaError instead, and guarded()
// turns the exception into a Lua error only after every C++ object of the body is destroyed.
#include <lua.hpp>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "engine/core/numbers.hpp"

namespace pitwall::lua {

struct LuaError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A number as a script wrote it: 600, -23.5, 0.25 (not 600.000000): engine/core/numbers.hpp.
inline std::string show(double v) {
  return formatNumber(v);
}

template <int (*Body)(lua_State*)>
int guarded(lua_State* L) {
  int results = 0;
  bool failed = false;
  try {
    results = Body(L);
  } catch (const std::exception& e) {
    lua_pushstring(L, e.what());
    failed = true;
  }
  if (failed) {
    // Prefix "file:line:" of the Lua code that called us, as luaL_error does.
    luaL_where(L, 1);
    lua_insert(L, -2);
    lua_concat(L, 2);
    return lua_error(L);
  }
  return results;
}

inline std::string typeName(lua_State* L, int idx) {
  return luaL_typename(L, idx);
}

inline double checkNumber(lua_State* L, int idx, const char* what) {
  int isnum = 0;
  double v = lua_tonumberx(L, idx, &isnum);
  if (!isnum) throw LuaError(std::string(what) + " must be a number, got " + typeName(L, idx));
  if (!std::isfinite(v)) throw LuaError(std::string(what) + " must be a finite number");
  return v;
}

// Raises engine/core/numbers.hpp's sentence when v is outside lo..hi; `why` (the range's reason)
// follows in parentheses.
inline void requireRange(std::string_view what, double v, double lo, double hi,
                         std::string_view unit = {}, std::string_view why = {}) {
  if (auto e = checkRange(what, v, lo, hi, unit))
    throw LuaError(why.empty() ? *e : *e + " (" + std::string(why) + ")");
}

inline double optNumber(lua_State* L, int idx, const char* what, double fallback) {
  return lua_isnoneornil(L, idx) ? fallback : checkNumber(L, idx, what);
}

// An integral number (600 or 600.0, not 600.5), range-checked by the caller.
inline long long checkInteger(lua_State* L, int idx, const char* what) {
  int isint = 0;
  lua_Integer v = lua_tointegerx(L, idx, &isint);
  if (isint) return v;
  if (lua_type(L, idx) == LUA_TNUMBER)
    throw LuaError(std::string(what) + " must be a whole number, got " +
                   show(lua_tonumber(L, idx)));
  throw LuaError(std::string(what) + " must be a whole number, got " + typeName(L, idx));
}

inline long long optInteger(lua_State* L, int idx, const char* what, long long fallback) {
  return lua_isnoneornil(L, idx) ? fallback : checkInteger(L, idx, what);
}

inline std::string checkString(lua_State* L, int idx, const char* what) {
  if (lua_type(L, idx) != LUA_TSTRING)
    throw LuaError(std::string(what) + " must be a string, got " + typeName(L, idx));
  size_t n = 0;
  const char* s = lua_tolstring(L, idx, &n);
  return std::string(s, n);
}

inline void checkFunction(lua_State* L, int idx, const char* what) {
  if (lua_type(L, idx) != LUA_TFUNCTION)
    throw LuaError(std::string(what) + " must be a function, got " + typeName(L, idx));
}

// Message handler for lua_pcall: the error text plus a traceback.
int traceback(lua_State* L);

// t[key] = value for the table on top of the stack.
inline void setInteger(lua_State* L, const char* key, lua_Integer v) {
  lua_pushinteger(L, v);
  lua_setfield(L, -2, key);
}
inline void setNumber(lua_State* L, const char* key, double v) {
  lua_pushnumber(L, v);
  lua_setfield(L, -2, key);
}
inline void setBoolean(lua_State* L, const char* key, bool v) {
  lua_pushboolean(L, v);
  lua_setfield(L, -2, key);
}
inline void setString(lua_State* L, const char* key, std::string_view v) {
  lua_pushlstring(L, v.data(), v.size());
  lua_setfield(L, -2, key);
}

// __index of a userdata type (cars, robots): a method (the methods table is upvalue 1), else a
// state field — `field(key)` pushes it and returns true —, else the object's own table (its
// uservalue 1), where the script keeps its handlers and fields.
template <class Field>
int indexObject(lua_State* L, Field&& field) {
  lua_pushvalue(L, 2);
  if (lua_rawget(L, lua_upvalueindex(1)) != LUA_TNIL) return 1;
  lua_pop(L, 1);
  if (lua_type(L, 2) == LUA_TSTRING && field(std::string_view(lua_tostring(L, 2)))) return 1;
  lua_getiuservalue(L, 1, 1);
  lua_pushvalue(L, 2);
  lua_rawget(L, -2);
  return 1;
}

inline std::string joinNames(std::span<const char* const> names) {
  std::string s;
  for (const char* n : names) s += (s.empty() ? "" : ", ") + std::string(n);
  return s;
}

// __newindex of a name that is no event: refuses, by name, what is not the script's to set — an
// onX that is no event (a typo would never be called), a state field, a method. `what` is how
// errors name the object ("car", "robot").
inline void refuseReserved(lua_State* L, const std::string& what, const std::string& key,
                           std::span<const char* const> fields,
                           std::span<const char* const> events) {
  if (key.size() > 2 && key[0] == 'o' && key[1] == 'n' &&
      std::isupper(static_cast<unsigned char>(key[2])))
    throw LuaError(what + "." + key + " is not an event; the events are " + joinNames(events));
  for (const char* f : fields)
    if (key == f)
      throw LuaError(what + "." + key + " is read-only (it is the " + what + "'s state)");
  lua_pushvalue(L, 2);
  bool isMethod = lua_rawget(L, lua_upvalueindex(1)) != LUA_TNIL;
  lua_pop(L, 1);
  if (isMethod) throw LuaError(what + ":" + key + " is a method and cannot be replaced");
}

// A handler set on an event: a function, or nil to remove it.
inline void checkHandler(lua_State* L, const std::string& what, const std::string& key) {
  if (!lua_isnil(L, 3) && !lua_isfunction(L, 3))
    throw LuaError(what + "." + key + " must be a function or nil, got " + typeName(L, 3));
}

// __newindex's end: object[key] = value in the object's own table (its uservalue 1).
inline int storeOwnField(lua_State* L) {
  lua_settop(L, 3);
  lua_getiuservalue(L, 1, 1);
  lua_pushvalue(L, 2);
  lua_pushvalue(L, 3);
  lua_rawset(L, 4);
  return 0;
}

// A userdata type seen from Lua (cars, robots): one metatable under `metatable` in the registry.
struct ObjectType {
  const char* metatable;  // registry key, "pitwall.car"
  const char* name;       // __name, "car"
  const luaL_Reg* methods;
  std::span<const char* const> fields;  // read-only state fields
  std::span<const char* const> events;  // onX handlers
  lua_CFunction index;                  // both get the methods table as upvalue 1
  lua_CFunction newindex;
  lua_CFunction tostring;
  lua_CFunction gc = nullptr;
};

// Registers the type's metatable (once): __index and __newindex as closures over the methods
// table, __tostring, __gc, __name, and __methods / __fields / __events, which the REPL completes
// from without calling __index (scripts/pitwall/repl.lua).
inline void registerObjectType(lua_State* L, const ObjectType& type) {
  if (!luaL_newmetatable(L, type.metatable)) {
    lua_pop(L, 1);
    return;
  }
  lua_newtable(L);
  luaL_setfuncs(L, type.methods, 0);
  lua_pushvalue(L, -1);
  lua_setfield(L, -3, "__methods");
  for (auto [names, key] :
       {std::pair{type.fields, "__fields"}, std::pair{type.events, "__events"}}) {
    lua_createtable(L, static_cast<int>(names.size()), 0);
    for (std::size_t i = 0; i < names.size(); ++i) {
      lua_pushstring(L, names[i]);
      lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
    }
    lua_setfield(L, -3, key);
  }
  lua_pushvalue(L, -1);
  lua_pushcclosure(L, type.index, 1);
  lua_setfield(L, -3, "__index");
  lua_pushcclosure(L, type.newindex, 1);
  lua_setfield(L, -2, "__newindex");
  lua_pushcfunction(L, type.tostring);
  lua_setfield(L, -2, "__tostring");
  if (type.gc) {
    lua_pushcfunction(L, type.gc);
    lua_setfield(L, -2, "__gc");
  }
  lua_pushstring(L, type.name);
  lua_setfield(L, -2, "__name");
  lua_pop(L, 1);
}

}  // namespace pitwall::lua
