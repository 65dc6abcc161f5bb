#include "bindings/car_lists.hpp"

#include "bindings/lua_object.hpp"

#include <algorithm>
#include <cctype>
#include <string_view>

#include "bindings/car_binding.hpp"
#include "engine/core/printable.hpp"
#include "engine/core/suggest.hpp"

namespace pitwall::lua {

namespace {

constexpr const char* kCarListMetatable = "pitwall.carlist";

// The note of the last miss: a table in the registry under this address (a light key: the
// registry's string keys are metatables, which are locked, and this is none).
char kNoteKey;

constexpr std::size_t kRollMax = 8;        // cars a sentence names; then how many more
constexpr lua_Integer kReadMax = 100'000;  // entries of a list the explainer reads at most
constexpr std::string_view kLuaSays = "attempt to index a nil value";

// A car list's __index: nil, as any table answers. When the line of a Lua function asked — not
// ipairs, whose probe one past the end is how it stops, nor another C function — a note of what
// was asked and where, overwriting the last one.
int missingCar(lua_State* L) {
  const int keyType = lua_type(L, 2);
  const bool worthNoting =
      lua_type(L, 1) == LUA_TTABLE &&
      ((keyType == LUA_TNUMBER && lua_isinteger(L, 2)) || keyType == LUA_TSTRING);
  lua_Debug ar;
  if (worthNoting && lua_getstack(L, 1, &ar) && lua_getinfo(L, "Sl", &ar) && ar.what[0] != 'C' &&
      ar.currentline > 0 && lua_checkstack(L, 4)) {
    if (lua_rawgetp(L, LUA_REGISTRYINDEX, &kNoteKey) != LUA_TTABLE) {
      lua_pop(L, 1);
      lua_createtable(L, 0, 6);
      lua_pushvalue(L, -1);
      lua_rawsetp(L, LUA_REGISTRYINDEX, &kNoteKey);
    }
    const int note = lua_gettop(L);
    lua_pushvalue(L, 1);
    lua_setfield(L, note, "list");  // a plain table: setfield is raw
    lua_pushvalue(L, 2);
    lua_setfield(L, note, "key");
    lua_pushlightuserdata(L, L);
    lua_setfield(L, note, "thread");
    lua_pushlightuserdata(L, const_cast<char*>(ar.source));  // the chunk's, as long as it lives
    lua_setfield(L, note, "source");
    lua_pushinteger(L, ar.linedefined);
    lua_setfield(L, note, "defined");
    lua_pushinteger(L, ar.currentline);
    lua_setfield(L, note, "line");
    lua_settop(L, 2);
  }
  lua_pushnil(L);
  return 1;
}

std::string roll(const std::vector<std::pair<long long, std::string>>& cars) {
  std::string out;
  for (std::size_t i = 0; i < cars.size() && i < kRollMax; ++i)
    out += (i ? ", " : "") + std::to_string(cars[i].first) + " " + printable(cars[i].second, 40);
  if (cars.size() > kRollMax) out += " and " + std::to_string(cars.size() - kRollMax) + " more";
  return out;
}

bool isIdentifier(std::string_view s) {
  return !s.empty() && !std::isdigit(static_cast<unsigned char>(s[0])) &&
         std::all_of(s.begin(), s.end(), [](char c) {
           return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
         });
}

}  // namespace

void makeCarList(lua_State* L, int idx) {
  lua::setTableType(L, idx, kCarListMetatable, "car list", missingCar);
}

bool isCarList(lua_State* L, int idx) {
  return lua::hasTableType(L, idx, kCarListMetatable);
}

std::string carsThereAre(const std::vector<std::pair<long long, std::string>>& cars) {
  if (cars.empty()) return "the run has no cars";
  return (cars.size() == 1 ? "the only car is " : "the cars are ") + roll(cars);
}

std::optional<std::string> explainMissingCar(lua_State* thread, int level,
                                             const std::string& message) {
  const auto at = message.find(kLuaSays);
  if (at == std::string::npos) return std::nullopt;
  // What Lua says the nil was: (field 'integer index'), (field '?'), (field 'name'), (local 'c').
  const std::string_view rest = std::string_view(message).substr(at + kLuaSays.size());
  const auto close = rest.find("')");
  if (!rest.starts_with(" (") || close == std::string_view::npos) return std::nullopt;
  const std::string_view what = rest.substr(2, close - 2);
  const auto end = at + kLuaSays.size() + close + 2;
  enum class Key { Integer, Name, Any } wanted;
  std::string_view field;
  if (what.starts_with("field '")) {
    field = what.substr(7);
    wanted = field == "integer index" ? Key::Integer : field == "?" ? Key::Any : Key::Name;
  } else if (what.starts_with("local '") || what.starts_with("upvalue '")) {
    wanted = Key::Any;
  } else {
    return std::nullopt;
  }

  // The Lua function whose line failed (a failed index leaves no frame of its own, but skip C
  // frames as the method explainer does).
  lua_Debug ar;
  for (;; ++level) {
    if (!lua_getstack(thread, level, &ar) || !lua_getinfo(thread, "Sl", &ar)) return std::nullopt;
    if (ar.what[0] != 'C') break;
    if (level > 8) return std::nullopt;
  }
  if (!lua_checkstack(thread, 12)) return std::nullopt;
  const int base = lua_gettop(thread);
  auto done = [&](std::optional<std::string> answer) {
    lua_settop(thread, base);
    return answer;
  };
  if (lua_rawgetp(thread, LUA_REGISTRYINDEX, &kNoteKey) != LUA_TTABLE) return done(std::nullopt);
  const int note = lua_gettop(thread);
  auto integerField = [&](const char* name) {
    lua::rawField(thread, note, name);
    const lua_Integer v = lua_isinteger(thread, -1) ? lua_tointeger(thread, -1) : -1;
    lua_pop(thread, 1);
    return v;
  };
  auto pointerField = [&](const char* name) {
    lua::rawField(thread, note, name);
    const void* p = lua_touserdata(thread, -1);
    lua_pop(thread, 1);
    return p;
  };
  // The note must be of this very line of this very function on this thread.
  if (pointerField("thread") != thread || pointerField("source") != ar.source ||
      integerField("defined") != ar.linedefined || integerField("line") != ar.currentline)
    return done(std::nullopt);
  const int keyType = lua::rawField(thread, note, "key");
  const int key = lua_gettop(thread);
  if (keyType == LUA_TNUMBER
          ? wanted == Key::Name
          : wanted == Key::Integer || (wanted == Key::Name && field != lua_tostring(thread, key)))
    return done(std::nullopt);
  if (lua::rawField(thread, note, "list") != LUA_TTABLE) return done(std::nullopt);
  const int list = lua_gettop(thread);

  // What the list holds: its cars by number, and the names it keys cars by (the REPL's `cars`).
  std::vector<std::pair<long long, std::string>> cars;
  std::vector<std::string> names;
  const lua_Integer length = std::min<lua_Integer>(lua_rawlen(thread, list), kReadMax);
  for (lua_Integer i = 1; i <= length; ++i) {
    lua_rawgeti(thread, list, i);
    if (AnkiCar* car = CarBinding::test(thread, -1)) cars.emplace_back(i, car->identity().name);
    lua_pop(thread, 1);
  }
  lua_pushnil(thread);
  for (lua_Integer read = 0; read < kReadMax && lua_next(thread, list) != 0; ++read) {
    if (lua_type(thread, -2) == LUA_TSTRING && CarBinding::test(thread, -1))
      names.emplace_back(lua_tostring(thread, -2));
    lua_pop(thread, 1);
  }
  lua_rawgeti(thread, LUA_REGISTRYINDEX, LUA_RIDX_GLOBALS);
  const bool global =
      lua::rawField(thread, -1, "cars") == LUA_TTABLE && lua_rawequal(thread, -1, list);

  std::string sentence;
  if (keyType == LUA_TNUMBER) {
    const std::string n = std::to_string(lua_tointeger(thread, key));
    sentence = global ? "cars[" + n + "] is nil: there is no car " + n + "; " + carsThereAre(cars)
                      : "this list of cars has no [" + n + "]; " +
                            (cars.empty() ? std::string("it is empty") : "it holds " + roll(cars));
  } else {
    const std::string name = lua_tostring(thread, key);
    const std::string shown = printable(name, 40);
    if (global) {
      sentence = (isIdentifier(name) ? "cars." + shown : "cars[\"" + shown + "\"]") +
                 " is nil: there is no car " + shown;
      std::string rest = carsThereAre(cars);
      if (auto near = nearest(name, names)) {
        rest[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(rest[0])));
        sentence += "; did you mean cars." + *near + "? " + rest;
      } else {
        sentence += "; " + rest;
      }
    } else {
      sentence =
          "this list of cars has no '" + shown + "'; " +
          (cars.empty() ? std::string("it is empty") : "it holds cars by number: " + roll(cars));
    }
  }
  lua_pushnil(thread);
  lua_rawsetp(thread, LUA_REGISTRYINDEX, &kNoteKey);  // told once
  return done(message.substr(0, at) + sentence + message.substr(end));
}

}  // namespace pitwall::lua
