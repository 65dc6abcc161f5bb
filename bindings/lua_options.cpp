// Option tables (`sim.addCar{…}`, `car:lights{…}`, `pitwall.mindroad{…}`): a key that is no
// option is a typo that would silently fall back to a default, so it is refused by name, with
// the option it was probably meant to be (engine/core/suggest.hpp).
#include <cstdio>
#include <string>
#include <vector>

#include "bindings/lua_options.hpp"

#include "bindings/lua_args.hpp"
#include "engine/core/printable.hpp"
#include "engine/core/suggest.hpp"

namespace pitwall::lua {

namespace {

constexpr std::size_t kMaxKeyShown = 40;  // bytes of a key an error shows, then "… (N bytes)"

// "the number key 1", "the boolean key true", "a table key" (no __tostring is called: it could
// raise an error through this C++ frame).
std::string keyShown(lua_State* L, int idx) {
  const std::string type = luaL_typename(L, idx);
  switch (lua_type(L, idx)) {
    case LUA_TNUMBER:
      return "the number key " +
             (lua_isinteger(L, idx) ? std::to_string(lua_tointeger(L, idx))
                                    : show(lua_tonumber(L, idx))) +
             " (a list where the options go?)";
    case LUA_TBOOLEAN:
      return std::string("the boolean key ") + (lua_toboolean(L, idx) ? "true" : "false");
    default:
      return "a " + type + " key";
  }
}

}  // namespace

void checkOptions(lua_State* L, int idx, std::string_view fn, std::span<const char* const> known) {
  if (lua_type(L, idx) != LUA_TTABLE) return;
  idx = lua_absindex(L, idx);
  luaL_checkstack(L, 3, "option table");
  std::string problem;
  std::string key;
  bool unknown = false;
  lua_pushnil(L);
  while (lua_next(L, idx) != 0) {
    lua_pop(L, 1);  // the value
    if (lua_type(L, -1) != LUA_TSTRING) {
      // (a number key is never turned into a string here: lua_tostring would confuse next)
      problem = "option names are strings, got " + keyShown(L, -1);
      lua_pop(L, 1);
      break;
    }
    std::size_t n = 0;
    const char* s = lua_tolstring(L, -1, &n);
    std::string_view k(s, n);
    bool found = false;
    for (const char* name : known)
      if (k == name) found = true;
    if (!found) {
      unknown = true;
      key.assign(s, n);
      lua_pop(L, 1);
      break;
    }
  }
  if (problem.empty() && !unknown) return;
  if (problem.empty()) {
    std::vector<std::string> names(known.begin(), known.end());
    // (a key far longer than any option is no typo of one: no edit distance over megabytes)
    problem = "unknown option " +
              (key.empty() ? std::string("\"\" (an empty name)") : printable(key, kMaxKeyShown)) +
              (key.size() > kMaxKeyShown ? " (" + std::to_string(key.size()) + " bytes)" : "") +
              (key.size() <= 64 ? didYouMean(key, names) : "");
  }
  std::string all;
  for (const char* name : known) all += (all.empty() ? "" : ", ") + std::string(name);
  throw LuaError(std::string(fn) + ": " + problem + " (the options are " + all + ")");
}

std::string unknownName(std::string_view what, std::string_view name,
                        std::span<const char* const> names) {
  std::vector<std::string> candidates(names.begin(), names.end());
  std::string all;
  for (std::size_t i = 0; i < names.size(); ++i)
    all += std::string(i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return std::string(what) + " '" + printable(std::string(name), kMaxKeyShown) + "' is unknown" +
         (name.size() <= 64 ? didYouMean(name, candidates) : "") + " (use " + all + ")";
}

Options::Options(lua_State* L, int idx, std::string_view fn, std::span<const char* const> known,
                 std::string_view shape)
    : L_(L), idx_(lua_absindex(L, idx)), fn_(fn), table_(lua_istable(L, idx)) {
  if (!table_ && !lua_isnoneornil(L, idx))
    throw LuaError(std::string(fn) + " takes a table {" + std::string(shape) + "}, got " +
                   typeName(L, idx));
  if (table_) checkOptions(L, idx_, fn, known);
}

bool Options::value(const char* key) {
  if (!table_) return false;
  if (lua_getfield(L_, idx_, key) != LUA_TNIL) return true;
  lua_pop(L_, 1);
  return false;
}

std::optional<std::string> Options::string(const char* key, const char* what) {
  if (!value(key)) return std::nullopt;
  std::string v = checkString(L_, -1, what ? what : key);
  lua_pop(L_, 1);
  return v;
}

std::optional<bool> Options::boolean(const char* key) {
  if (!value(key)) return std::nullopt;
  if (!lua_isboolean(L_, -1))
    throw LuaError(std::string(key) + " must be true or false, got " + typeName(L_, -1));
  const bool v = lua_toboolean(L_, -1);
  lua_pop(L_, 1);
  return v;
}

std::optional<double> Options::number(const char* key, double lo, double hi, std::string_view unit,
                                      std::string_view why) {
  if (!value(key)) return std::nullopt;
  const double v = checkNumber(L_, -1, key);
  lua_pop(L_, 1);
  requireRange(key, v, lo, hi, unit, why);
  return v;
}

std::optional<double> Options::number(const char* key, const char* what) {
  if (!value(key)) return std::nullopt;
  const double v = checkNumber(L_, -1, what);
  lua_pop(L_, 1);
  return v;
}

std::optional<long long> Options::integer(const char* key, long long lo, long long hi,
                                          std::string_view unit, std::string_view why) {
  if (!value(key)) return std::nullopt;
  const long long v = checkInteger(L_, -1, key);
  lua_pop(L_, 1);
  requireRange(key, static_cast<double>(v), static_cast<double>(lo), static_cast<double>(hi), unit,
               why);
  return v;
}

}  // namespace pitwall::lua
