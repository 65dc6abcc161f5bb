#include "bindings/misspelled_method.hpp"

#include <algorithm>
#include <string_view>
#include <vector>

#include "bindings/car_lists.hpp"
#include "bindings/lua_args.hpp"
#include "engine/core/suggest.hpp"

namespace pitwall::lua {

namespace {

constexpr std::string_view kLuaSays = "attempt to call a nil value (method '";
constexpr std::string_view kLuaSaysField = "attempt to call a nil value (field '";

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

// The kind of the object on top of L's stack, when it has methods; pops nothing. Only raw reads:
// a metatable's own __index (a "strict" guard, a loop) never runs here.
std::optional<Kind> kindOf(lua_State* L) {
  if (!lua_checkstack(L, 8)) return std::nullopt;
  const int obj = lua_gettop(L);
  if (!lua_getmetatable(L, obj)) return std::nullopt;
  const int mt = lua_gettop(L);
  std::optional<Kind> kind;
  if (lua::rawField(L, mt, "__name") == LUA_TSTRING) {
    kind = Kind{lua_tostring(L, -1), {}};
    if (lua::rawField(L, mt, "__methods") == LUA_TTABLE) {
      addFunctionKeys(L, lua_gettop(L), kind->methods);
    } else {
      // a Lua class: the functions of its __index chain (a few levels of inheritance)
      lua_pop(L, 1);
      if (lua_type(L, obj) == LUA_TTABLE) addFunctionKeys(L, obj, kind->methods);
      lua_pushvalue(L, mt);
      for (int depth = 0; depth < 8; ++depth) {
        if (lua::rawField(L, -1, "__index") != LUA_TTABLE) {
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

// The first Lua function from `level` of `thread`: the one whose call failed (a failed call may
// leave a frame of the called value above it, "[C]: in method 'x'").
// Lua's sentence `says` in `message` ("attempt to call a nil value (field '") and the name it
// quotes: where the sentence begins, where the quote ends (past "')"), the name.
struct Quoted {
  std::size_t at, end;
  std::string name;
};
std::optional<Quoted> luaSays(const std::string& message, std::string_view says) {
  const auto at = message.find(says);
  if (at == std::string::npos) return std::nullopt;
  const auto nameStart = at + says.size();
  const auto nameEnd = message.find("')", nameStart);
  if (nameEnd == std::string::npos) return std::nullopt;
  return Quoted{at, nameEnd + 2, message.substr(nameStart, nameEnd - nameStart)};
}

bool failedFunction(lua_State* thread, int level, lua_Debug& ar) {
  for (;; ++level) {
    if (!lua_getstack(thread, level, &ar)) return false;
    if (!lua_getinfo(thread, "S", &ar)) return false;
    if (ar.what[0] != 'C') return true;
    if (level > 8) return false;
  }
}

// A library table: where it is on the stack and how it is named.
struct Library {
  int index;
  std::string name;   // as the failing function sees it ("pitwall", "race", "pitwall.sim")
  bool seen = false;  // the failing function can see it (a local, an upvalue, a global, a field)
};

// The library's tables, pushed on `L` (raw reads of package.loaded and the pitwall table):
// "pitwall", every "pitwall.X" module (named X, as `local X = require "pitwall.X"` names it)
// and the tables in pitwall (pitwall.sim, pitwall.view; not persist, which holds the script's
// own data).
std::vector<Library> libraries(lua_State* L) {
  std::vector<Library> out;
  auto known = [&](int idx) {
    for (const Library& l : out)
      if (lua_rawequal(L, l.index, idx)) return true;
    return false;
  };
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);  // never made: the host opened it
  const int loaded = lua_gettop(L);
  if (lua::rawField(L, loaded, "pitwall") == LUA_TTABLE) {
    const int pitwall = lua_gettop(L);
    out.push_back({pitwall, "pitwall"});
    lua_pushnil(L);
    while (lua_next(L, pitwall) != 0 && lua_checkstack(L, 4) && out.size() < 64) {
      if (lua_type(L, -2) == LUA_TSTRING && lua_istable(L, -1) && !known(-1) &&
          std::string_view(lua_tostring(L, -2)) != "persist") {
        const std::string key = lua_tostring(L, -2);
        lua_insert(L, -2);  // the table stays on the stack, under the key lua_next goes on with
        out.push_back({lua_gettop(L) - 1, "pitwall." + key});
        continue;
      }
      lua_pop(L, 1);
    }
  } else {
    lua_pop(L, 1);
  }
  lua_pushnil(L);
  while (lua_next(L, loaded) != 0 && lua_checkstack(L, 4) && out.size() < 64) {
    if (lua_type(L, -2) == LUA_TSTRING && lua_istable(L, -1) && !known(-1)) {
      const std::string_view key = lua_tostring(L, -2);
      if (key.starts_with("pitwall.")) {
        const std::string name(key.substr(8));
        lua_insert(L, -2);
        out.push_back({lua_gettop(L) - 1, name});
        continue;
      }
    }
    lua_pop(L, 1);
  }
  return out;
}

}  // namespace

std::optional<std::string> explainMissingFunction(lua_State* thread, int level,
                                                  const std::string& message) {
  auto said = luaSays(message, kLuaSaysField);
  if (!said) return std::nullopt;
  const auto at = said->at;
  const std::string& field = said->name;
  lua_Debug ar;
  if (!failedFunction(thread, level, ar) || !lua_checkstack(thread, 80)) return std::nullopt;
  const int base = lua_gettop(thread);
  std::vector<Library> libs = libraries(thread);

  // Which of them the failing function can see, and by what name: its locals, its upvalues, the
  // globals of its _ENV; then the tables in those (pitwall.sim as `pitwall.sim`).
  auto see = [&](int idx, const std::string& name) {
    for (Library& l : libs)
      if (!l.seen && lua_rawequal(thread, l.index, idx)) {
        l.name = name;
        l.seen = true;
      }
  };
  // The globals of a table (an _ENV): the names of the library tables in it.
  auto seeGlobals = [&](int table) {
    lua_pushnil(thread);
    for (int read = 0; lua_next(thread, table) != 0; ++read) {
      if (lua_type(thread, -2) == LUA_TSTRING && lua_istable(thread, -1))
        see(lua_gettop(thread), lua_tostring(thread, -2));
      lua_pop(thread, 1);
      if (read == 100'000) {  // a script's huge global table: enough
        lua_pop(thread, 1);
        break;
      }
    }
  };
  for (int n = 1;; ++n) {
    const char* name = lua_getlocal(thread, &ar, n);
    if (!name) break;
    if (name[0] != '(' && lua_istable(thread, -1)) see(lua_gettop(thread), name);
    lua_pop(thread, 1);
  }
  if (lua_getinfo(thread, "f", &ar)) {
    const int fn = lua_gettop(thread);
    for (int n = 1;; ++n) {
      const char* name = lua_getupvalue(thread, fn, n);
      if (!name) break;
      const int up = lua_gettop(thread);
      if (lua_istable(thread, up)) {
        if (std::string_view(name) == "_ENV") {
          seeGlobals(up);
          // an _ENV of its own (the REPL's prompt) reads the world's globals through its
          // __index, a function the handler does not call: the globals themselves then
          lua_rawgeti(thread, LUA_REGISTRYINDEX, LUA_RIDX_GLOBALS);
          if (!lua_rawequal(thread, -1, up)) seeGlobals(lua_gettop(thread));
          lua_pop(thread, 1);
        } else {
          see(up, name);
        }
      }
      lua_pop(thread, 1);
    }
    lua_pop(thread, 1);
  }
  for (std::size_t i = 0; i < libs.size(); ++i) {
    if (!libs[i].seen) continue;
    lua_pushnil(thread);
    while (lua_next(thread, libs[i].index) != 0) {
      if (lua_type(thread, -2) == LUA_TSTRING && lua_istable(thread, -1))
        see(lua_gettop(thread), libs[i].name + "." + lua_tostring(thread, -2));
      lua_pop(thread, 1);
    }
  }

  // Those that lack the name and have a function near it.
  std::vector<std::string> tables, suggestions;
  for (const Library& l : libs) {
    if (!l.seen) continue;
    if (lua::rawField(thread, l.index, field.c_str()) != LUA_TNIL) {
      lua_pop(thread, 1);
      continue;
    }
    lua_pop(thread, 1);
    std::vector<std::string> functions;
    addFunctionKeys(thread, l.index, functions);
    if (auto near = nearest(field, functions)) {
      tables.push_back(l.name);
      suggestions.push_back(l.name + "." + *near);
    }
  }
  lua_settop(thread, base);
  if (tables.empty()) return std::nullopt;
  auto either = [](const std::vector<std::string>& words, const char* joint) {
    std::string out;
    for (std::size_t i = 0; i < words.size(); ++i)
      out += (i == 0 ? "" : i + 1 == words.size() ? joint : ", ") + words[i];
    return out;
  };
  const std::string sentence =
      tables.size() == 1
          ? tables[0] + " has no function " + field + "; did you mean " + suggestions[0] + "?"
          : "neither " + either(tables, " nor ") + " has a function " + field + "; did you mean " +
                either(suggestions, " or ") + "?";
  return message.substr(0, at) + sentence + message.substr(said->end);
}

std::optional<std::string> explainMissingName(lua_State* thread, int level,
                                              const std::string& message) {
  if (auto explained = explainMissingMethod(thread, level, message)) return explained;
  if (auto explained = explainMissingFunction(thread, level, message)) return explained;
  return explainMissingCar(thread, level, message);
}

std::optional<std::string> explainMissingMethod(lua_State* thread, int level,
                                                const std::string& message) {
  auto said = luaSays(message, kLuaSays);
  if (!said) return std::nullopt;
  const auto at = said->at;
  const std::string& method = said->name;

  // The Lua function that made the call: the first Lua frame from `level` (a failed call may
  // leave a frame of the called value above it, "[C]: in method 'x'").
  lua_Debug ar;
  if (!failedFunction(thread, level, ar) || !lua_checkstack(thread, 4)) return std::nullopt;
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
  return message.substr(0, at) + sentence + message.substr(said->end);
}

}  // namespace pitwall::lua
