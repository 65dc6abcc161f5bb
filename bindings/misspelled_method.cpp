#include "bindings/misspelled_method.hpp"

#include <algorithm>
#include <string_view>
#include <vector>

#include "engine/core/suggest.hpp"

namespace pitwall::lua {

namespace {

constexpr std::string_view kLuaSays = "attempt to call a nil value (method '";

struct Kind {
  std::string name;                  // "car"
  std::vector<std::string> methods;  // its method names
};

void addFunctionKeys(lua_State* L, int table, std::vector<std::string>& out) {
  lua_pushnil(L);
  while (lua_next(L, table) != 0) {
    if (lua_type(L, -2) == LUA_TSTRING && lua_isfunction(L, -1)) {
      std::string key = lua_tostring(L, -2);
      if (key.rfind("__", 0) != 0) out.push_back(std::move(key));
    }
    lua_pop(L, 1);
  }
}

// t[key] without metamethods (t at index t): nothing of the script runs inside an error handler.
int rawField(lua_State* L, int t, const char* key) {
  t = lua_absindex(L, t);
  lua_pushstring(L, key);
  return lua_rawget(L, t);
}

// The kind of the object on top of L's stack, when it has methods; pops nothing. Only raw reads:
// a metatable's own __index (a "strict" guard, a loop) never runs here.
std::optional<Kind> kindOf(lua_State* L) {
  if (!lua_checkstack(L, 8)) return std::nullopt;
  const int obj = lua_gettop(L);
  if (!lua_getmetatable(L, obj)) return std::nullopt;
  const int mt = lua_gettop(L);
  std::optional<Kind> kind;
  if (rawField(L, mt, "__name") == LUA_TSTRING) {
    kind = Kind{lua_tostring(L, -1), {}};
    if (rawField(L, mt, "__methods") == LUA_TTABLE) {
      addFunctionKeys(L, lua_gettop(L), kind->methods);
    } else {
      // a Lua class: the functions of its __index chain (a few levels of inheritance)
      lua_pop(L, 1);
      if (lua_type(L, obj) == LUA_TTABLE) addFunctionKeys(L, obj, kind->methods);
      lua_pushvalue(L, mt);
      for (int depth = 0; depth < 8; ++depth) {
        if (rawField(L, -1, "__index") != LUA_TTABLE) {
          lua_pop(L, 1);
          break;
        }
        addFunctionKeys(L, lua_gettop(L), kind->methods);
        lua_remove(L, -2);
        if (!lua_getmetatable(L, -1)) break;
        lua_remove(L, -2);
      }
      if (kind->methods.empty()) kind.reset();
    }
  }
  lua_settop(L, obj);
  return kind;
}

}  // namespace

std::optional<std::string> explainMissingMethod(lua_State* thread, int level,
                                                const std::string& message) {
  const auto at = message.find(kLuaSays);
  if (at == std::string::npos) return std::nullopt;
  const auto nameStart = at + kLuaSays.size();
  const auto nameEnd = message.find("')", nameStart);
  if (nameEnd == std::string::npos) return std::nullopt;
  const std::string method = message.substr(nameStart, nameEnd - nameStart);

  // The Lua function that made the call: the first Lua frame from `level` (a failed call may
  // leave a frame of the called value above it, "[C]: in method 'x'").
  lua_Debug ar;
  for (;; ++level) {
    if (!lua_getstack(thread, level, &ar)) return std::nullopt;
    if (!lua_getinfo(thread, "S", &ar)) return std::nullopt;
    if (ar.what[0] != 'C') break;
    if (level > 8) return std::nullopt;
  }
  if (!lua_checkstack(thread, 4)) return std::nullopt;
  // Candidates: a nil temporary (the method's register) followed by an object with methods
  // (its `self`); pending arguments of an outer call may form such pairs too. A type that has the
  // method is never named; of the others, the first whose type has a method near the name wins,
  // else the first.
  std::optional<Kind> chosen;
  std::optional<std::string> suggestion;
  bool previousNil = false;
  for (int n = 1;; ++n) {
    const char* name = lua_getlocal(thread, &ar, n);
    if (!name) break;
    const bool temporary = name[0] == '(';
    if (temporary && previousNil) {
      auto kind = kindOf(thread);
      if (kind &&
          std::find(kind->methods.begin(), kind->methods.end(), method) == kind->methods.end()) {
        auto near = nearest(method, kind->methods);
        if (!chosen || (near && !suggestion)) {
          chosen = std::move(kind);
          suggestion = std::move(near);
        }
      }
    }
    previousNil = temporary && lua_isnil(thread, -1);
    lua_pop(thread, 1);
    if (suggestion) break;
  }
  if (!chosen) return std::nullopt;
  std::string sentence = chosen->name + " has no method " + method;
  if (suggestion) sentence += "; did you mean " + *suggestion + "?";
  return message.substr(0, at) + sentence + message.substr(nameEnd + 2);
}

}  // namespace pitwall::lua
