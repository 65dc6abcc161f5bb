// Option tables (`sim.addCar{…}`, `car:lights{…}`, `pitwall.mindroad{…}`): a key that is no
// option is a typo that would silently fall back to a default, so it is refused by name, with
// the option it was probably meant to be (engine/core/suggest.hpp).
#include <cstdio>
#include <string>
#include <vector>

#include "bindings/lua_args.hpp"
#include "engine/core/suggest.hpp"

namespace pitwall::lua {

namespace {

// The length of the UTF-8 character at the start of s (2..4), or 0 when it is none.
std::size_t utf8Length(std::string_view s) {
  auto c = static_cast<unsigned char>(s[0]);
  std::size_t n = c >= 0xf0 && c <= 0xf4 ? 4 : c >= 0xe0 ? 3 : c >= 0xc2 && c < 0xe0 ? 2 : 0;
  if (n == 0 || s.size() < n) return 0;
  for (std::size_t i = 1; i < n; ++i)
    if ((static_cast<unsigned char>(s[i]) & 0xc0) != 0x80) return 0;
  // no overlong forms, no surrogates, nothing beyond U+10FFFF (RFC 3629)
  auto second = static_cast<unsigned char>(s[1]);
  if ((c == 0xe0 && second < 0xa0) || (c == 0xed && second > 0x9f) ||
      (c == 0xf0 && second < 0x90) || (c == 0xf4 && second > 0x8f))
    return 0;
  return n;
}

// A key as an error may show it: printable text as it is (UTF-8 included: `vitésse`), other
// bytes (control characters, invalid UTF-8) as \xNN, and at most the first 40 bytes of it.
std::string printable(std::string_view key) {
  constexpr std::size_t kMax = 40;
  std::string out;
  for (std::size_t i = 0; i < key.size() && i < kMax;) {
    auto c = static_cast<unsigned char>(key[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
      ++i;
    } else if (std::size_t n = c >= 0x80 ? utf8Length(key.substr(i)) : 0; n > 0) {
      out.append(key.substr(i, n));
      i += n;
    } else {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
      ++i;
    }
  }
  if (key.size() > kMax) out += "… (" + std::to_string(key.size()) + " bytes)";
  return out;
}

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
      key.assign(s, n);
      lua_pop(L, 1);
      break;
    }
  }
  if (problem.empty() && key.empty()) return;
  if (problem.empty()) {
    std::vector<std::string> names(known.begin(), known.end());
    // (a key far longer than any option is no typo of one: no edit distance over megabytes)
    problem = "unknown option " + printable(key) + (key.size() <= 64 ? didYouMean(key, names) : "");
  }
  std::string all;
  for (const char* name : known) all += (all.empty() ? "" : ", ") + std::string(name);
  throw LuaError(std::string(fn) + ": " + problem + " (the options are " + all + ")");
}

}  // namespace pitwall::lua
