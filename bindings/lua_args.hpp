#pragma once
// Arguments and errors, the tools every binding body uses: reading a Lua argument as what it
// must be (a number, a whole number in a range, a string, a function), writing event-table
// fields, and raising errors. Lua raises errors with longjmp, which must never cross a C++ frame
// holding live objects (LÖVE's rule): binding bodies throw LuaError instead, and guarded() turns
// the exception into a Lua error only after every C++ object of the body is destroyed.
#include <lua.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "bindings/protected_call.hpp"
#include "engine/core/numbers.hpp"

// A type's events, one X-macro list (X(Position) X(Transition) …), made into its enum's entries
// and its names ("onPosition", …).
#define PITWALL_EVENT_ENUM(name) name,
#define PITWALL_EVENT_NAME(name) "on" #name,

namespace pitwall::lua {

struct LuaError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A number as a script wrote it: 600, -23.5, 0.25 (not 600.000000): engine/core/numbers.hpp.
inline std::string show(double v) {
  return formatNumber(v);
}

// guarded's blame, "file:line: " of the user's line: pushUserWhere (bindings/protected_call.hpp).
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
    // Prefix "file:line:" of the script's line that called us (userWhere), as luaL_error does.
    pushUserWhere(L);
    lua_insert(L, -2);
    lua_concat(L, 2);
    return lua_error(L);
  }
  return results;
}

// A vehicle model's answer to a command (Sent: true, or the sentence why nothing was sent),
// the sentence raised; else 0, the command method's results: `return raiseIfRefused(…)`.
template <class Sent>
int raiseIfRefused(const Sent& sent) {
  if (!sent) throw LuaError(sent.error());
  return 0;
}

// A method that takes no argument and sends one command, robot:stop(): command<modelAt,
// &Model::stop>, where modelAt(L, 1) is the object's model (checked: another object raises).
template <auto ModelAt, auto Method>
int command(lua_State* L) {
  return raiseIfRefused((ModelAt(L, 1).*Method)());
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

// A whole quantity a script may well compute (a speed, an acceleration, a coordinate):
// a number that is not whole is rounded half away from zero (600.5 → 601, -0.5 → -1), the
// command's range check then sees the rounded value (docs/lua-api.md "Numbers").
inline long long checkRounded(lua_State* L, int idx, const char* what) {
  int isint = 0;
  lua_Integer v = lua_tointegerx(L, idx, &isint);
  if (isint) return v;
  double d = checkNumber(L, idx, what);
  // beyond ±1e15 no command's range reaches: clamp before converting (no overflow)
  return static_cast<long long>(std::round(std::clamp(d, -1e15, 1e15)));
}

inline long long optRounded(lua_State* L, int idx, const char* what, long long fallback) {
  return lua_isnoneornil(L, idx) ? fallback : checkRounded(L, idx, what);
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

// t[key] without metamethods (t at index t), its type: nothing of the script runs.
inline int rawField(lua_State* L, int t, const char* key) {
  t = lua_absindex(L, t);
  lua_pushstring(L, key);
  return lua_rawget(L, t);
}

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

}  // namespace pitwall::lua
