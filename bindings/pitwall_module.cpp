#include "bindings/pitwall_module.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "bindings/car_binding.hpp"
#include "bindings/car_lists.hpp"
#include "bindings/copy_budget.hpp"
#include "bindings/lua_args.hpp"
#include "bindings/lua_json.hpp"
#include "bindings/lua_object.hpp"
#include "bindings/lua_options.hpp"
#include "bindings/metatables.hpp"
#include "bindings/script_host.hpp"
#include "bindings/track_table.hpp"
#include "engine/core/console.hpp"
#include "engine/core/log.hpp"
#include "engine/core/printable.hpp"
#include "engine/core/suggest.hpp"
#include "engine/protocol/anki/pieces.hpp"
#include "engine/record/results.hpp"
#include "engine/sim/track.hpp"
#include "engine/sim/world.hpp"

namespace pitwall {

using lua::LuaError;

namespace {

constexpr const char* kTimerMetatable = "pitwall.timer";

Duration checkDelay(lua_State* L, int idx, const char* what, bool allowZero) {
  double s = lua::checkNumber(L, idx, what);
  if (s < 0 || (!allowZero && s <= 0))
    throw LuaError(std::string(what) + " must be " + (allowZero ? "≥ 0" : "> 0") +
                   " seconds, got " + lua::show(s));
  if (s > 1e9) throw LuaError(std::string(what) + " is too large: " + lua::show(s) + " s");
  return fromSeconds(s);
}

int cars(lua_State* L) {
  ScriptHost& host = ScriptHost::from(L);
  const auto& all = host.fleet().cars();
  lua_createtable(L, static_cast<int>(all.size()), 0);
  int i = 0;
  for (AnkiCar* car : all) {
    host.cars().push(L, *car);
    lua_rawseti(L, -2, ++i);
  }
  lua::makeCarList(L, -1);  // cars[9]:setSpeed(…) is an error naming the cars (car_lists.hpp)
  return 1;
}

// The car with that number or name; a car that is not there is an error naming those that are
// (docs/lua-api.md "Cars that are not there").
int car(lua_State* L) {
  ScriptHost& host = ScriptHost::from(L);
  AnkiCar* found = nullptr;
  std::string asked, name;
  std::vector<std::pair<long long, std::string>> cars;
  std::vector<std::string> names;
  for (AnkiCar* c : host.fleet().cars()) {
    cars.emplace_back(c->identity().number, c->identity().name);
    names.push_back(c->identity().name);
  }
  if (lua_type(L, 1) == LUA_TNUMBER) {
    const long long number = lua::checkInteger(L, 1, "car number");
    if (number >= 1 && number <= std::numeric_limits<int>::max())
      found = host.fleet().find(static_cast<int>(number));
    asked = "no car " + std::to_string(number);
  } else {
    name = lua::checkString(L, 1, "car name or number");
    for (AnkiCar* c : host.fleet().cars())
      if (c->identity().name == name) found = c;
    asked = "no car named '" + printable(name, 40) + "'";
  }
  if (!found) {
    std::string there = lua::carsThereAre(cars);
    if (auto near = name.empty() ? std::nullopt : nearest(name, names)) {
      there[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(there[0])));
      throw LuaError("pitwall.car: " + asked + "; did you mean " + printable(*near, 40) + "? " +
                     there);
    }
    throw LuaError("pitwall.car: " + asked + "; " + there);
  }
  host.cars().push(L, *found);
  return 1;
}

int now(lua_State* L) {
  lua_pushnumber(L, ScriptHost::from(L).loop().seconds());
  return 1;
}

const lua::TypeSpec& timerType();

int pushTimer(lua_State* L, int handle) {
  lua::newBox<int>(L, timerType(), handle);  // its handle in Timers
  return 1;
}

int after(lua_State* L) {
  Duration d = checkDelay(L, 1, "pitwall.after delay", true);
  lua::checkFunction(L, 2, "pitwall.after callback");
  lua_settop(L, 2);
  return pushTimer(L, ScriptHost::from(L).timers().add(L, d, std::nullopt));
}

int every(lua_State* L) {
  Duration d = checkDelay(L, 1, "pitwall.every period", false);
  if (d < std::chrono::milliseconds(1))
    throw LuaError("pitwall.every period must be at least 0.001 seconds, got " +
                   lua::show(lua_tonumber(L, 1)));
  lua::checkFunction(L, 2, "pitwall.every callback");
  lua_settop(L, 2);
  return pushTimer(L, ScriptHost::from(L).timers().add(L, d, d));
}

int cancelTimer(lua_State* L) {
  lua_pushboolean(L, ScriptHost::from(L).timers().cancel(lua::check<int>(L, 1, timerType())));
  return 1;
}

int spawn(lua_State* L) {
  lua::checkFunction(L, 1, "pitwall.spawn's argument");
  std::string name = lua_isnoneornil(L, 2) ? "" : lua::checkString(L, 2, "task name");
  if (name.empty()) {
    lua_Debug ar;
    if (lua_getstack(L, 1, &ar) && lua_getinfo(L, "Sl", &ar))
      name = std::string(ar.short_src) + ":" + std::to_string(ar.currentline);
    else
      name = "task";
  }
  lua_settop(L, 1);
  ScriptHost::from(L).tasks().spawn(L, name);
  return 0;
}

int sleepBody(lua_State* L) {
  Duration d = checkDelay(L, 1, "pitwall.sleep time", true);
  if (!lua_isyieldable(L))
    throw LuaError(
        "pitwall.sleep works only inside a task (pitwall.spawn or the script's main chunk); "
        "callbacks must return quickly — start a task from the callback instead");
  ScriptHost::from(L).tasks().sleep(L, d);
  return -1;  // the caller yields
}

// Not guarded<>: lua_yield must be the last call of the C function itself.
int sleep(lua_State* L) {
  int r = lua::guarded<sleepBody>(L);
  if (r == -1) return lua_yield(L, 0);
  return r;
}

int stop(lua_State* L) {
  ScriptHost::from(L).requestStop();
  return 0;
}

int logBody(lua_State* L) {
  int n = lua_gettop(L);
  log::Level level = log::Level::Info;
  int first = 1;
  if (n >= 2 && lua_type(L, 1) == LUA_TSTRING) {
    if (auto l = log::parseLevel(lua_tostring(L, 1))) {
      level = *l;
      first = 2;
    }
  }
  std::string text;
  for (int i = first; i <= n; ++i) {
    if (i > first) text += ' ';
    text += luaL_tolstring(L, i, nullptr);
    lua_pop(L, 1);
  }
  lua_Debug ar;
  std::string where = "script";
  if (lua_getstack(L, 1, &ar) && lua_getinfo(L, "Sl", &ar)) {
    if (lua::isLibrarySource(L, ar.source)) {  // the world's library (lua::Frames)
      // pitwall's own library says what it is about ("race: scan lap with …"): no file and
      // line of an installed file that is not the user's
      const auto colon = text.find(": ");
      const bool named =
          colon != std::string::npos && colon > 0 && colon <= 16 && text.find(' ') > colon;
      where = named ? text.substr(0, colon) : "pitwall";
      if (named) text.erase(0, colon + 2);
    } else {
      where = std::string(ar.short_src) + ":" + std::to_string(ar.currentline);
    }
  }
  log::write(level, where, text);
  return 0;
}

// pitwall._reportError(where, message): an error caught by the Lua library (a listener's),
// reported like an error in a handler: the log, or pitwall.onError; in tests a failure.
int reportError(lua_State* L) {
  std::string where = lua::checkString(L, 1, "where the error happened");
  std::string message = luaL_tolstring(L, 2, nullptr);
  ScriptHost::from(L).reportError(where, message);
  return 0;
}

// pitwall._raise(message): the Lua library's error(), naming the script's line that called into
// the library (lua::pushUserWhere), however deep inside the library it was raised.
int raise(lua_State* L) {
  throw LuaError(luaL_tolstring(L, 1, nullptr));
}

// The strings of the list at idx (other values are skipped).
std::vector<std::string> stringList(lua_State* L, int idx, const char* what) {
  if (!lua_istable(L, idx)) throw LuaError(std::string(what) + " must be a list of names");
  std::vector<std::string> out;
  for (lua_Integer i = 1, n = luaL_len(L, idx); i <= n; ++i) {
    if (lua_geti(L, idx, i) == LUA_TSTRING) out.emplace_back(lua_tostring(L, -1));
    lua_pop(L, 1);
  }
  return out;
}

// pitwall._nearest(word, names): the name `word` was probably meant to be (a typo of it), or
// nil — engine/core/suggest.hpp, for the Lua library's errors.
int nearestName(lua_State* L) {
  std::string word = lua::checkString(L, 1, "word");
  auto names = stringList(L, 2, "names");
  auto found = nearest(word, names);
  if (!found) return 0;
  lua_pushlstring(L, found->data(), found->size());
  return 1;
}

// pitwall._modulesIn("pitwall.drivers"): the sorted names of the Lua modules `require` finds
// under that prefix — the files <dir>/pitwall/drivers/*.lua for every <dir>/?.lua of
// package.path (drivers.load lists them when a name is not found).
int modulesIn(lua_State* L) {
  namespace fs = std::filesystem;
  std::string prefix = lua::checkString(L, 1, "module prefix");
  std::replace(prefix.begin(), prefix.end(), '.', '/');
  lua_getglobal(L, "package");
  std::string path = lua_istable(L, -1) && lua_getfield(L, -1, "path") == LUA_TSTRING
                         ? lua_tostring(L, -1)
                         : std::string();
  std::vector<std::string> names;
  for (std::size_t at = 0; at <= path.size();) {
    auto end = path.find(';', at);
    if (end == std::string::npos) end = path.size();
    std::string entry = path.substr(at, end - at);
    at = end + 1;
    if (!entry.ends_with("?.lua")) continue;
    fs::path folder = fs::path(entry.substr(0, entry.size() - 5)) / prefix;
    std::error_code ec;
    for (fs::directory_iterator it(folder, ec), done; !ec && it != done; it.increment(ec))
      if (it->path().extension() == ".lua") names.push_back(it->path().stem().string());
  }
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  lua_createtable(L, static_cast<int>(names.size()), 0);
  for (std::size_t i = 0; i < names.size(); ++i) {
    lua_pushlstring(L, names[i].data(), names[i].size());
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  return 1;
}

// pitwall._checkOptions(fnName, options, known): the Lua library's option tables, checked as the
// bindings' are (lua::checkOptions): an unknown key is an error on the script's line.
int checkOptionsOf(lua_State* L) {
  std::string fn = lua::checkString(L, 1, "function name");
  auto names = stringList(L, 3, "known options");
  std::vector<const char*> known;
  for (const auto& n : names) known.push_back(n.c_str());
  lua::checkOptions(L, 2, fn, known);
  return 0;
}

// The layout the cars are on: the simulator's track, or --ble --track's; none known: null.
const sim::Track* knownLayout(ScriptHost& host) {
  return host.sim() && host.sim()->world ? &host.sim()->world->track() : host.options().design;
}

// pitwall.layout(): that layout as sim.track() gives it, or nil (real cars without --track).
int layout(lua_State* L) {
  const sim::Track* known = knownLayout(ScriptHost::from(L));
  if (!known) {
    lua_pushnil(L);
    return 1;
  }
  pushTrackTable(L, *known);
  return 1;
}

// pitwall.piece(id): what a road piece is (docs/lua-api.md "Track pieces"), nil when unknown:
// Anki's stock pieces, and the custom pieces of the simulator's track or of --ble --track's
// layout (docs/tracks.md).
int piece(lua_State* L) {
  auto id = lua::checkInteger(L, 1, "piece id");
  if (id < 0 || id > 255) {
    lua_pushnil(L);
    return 1;
  }
  sim::Piece found{static_cast<std::uint8_t>(id), anki::pieceType(static_cast<std::uint8_t>(id))};
  bool known = found.type != anki::PieceType::Unknown;
  ScriptHost& host = ScriptHost::from(L);
  const sim::Track* layout = knownLayout(host);
  if (!known && layout)
    for (const sim::Piece& p : layout->pieces())
      if (p.id == id) {  // a custom id: its shape is the layout's
        found = p;
        known = true;
        break;
      }
  if (!known) {
    lua_pushnil(L);
    return 1;
  }
  lua_createtable(L, 0, 6);
  lua::setInteger(L, "id", id);
  lua::setString(L, "type", anki::pieceTypeName(found.type));
  if (found.type == anki::PieceType::Curve && found.turn == 0) found.turn = 1;  // either way
  lua::setNumber(L, "length", found.length(0));
  if (found.turn != 0) {
    lua::setNumber(L, "radius", found.radius());
    lua::setNumber(L, "angle", found.angle());
  }
  if (anki::pieceType(found.id) == anki::PieceType::Unknown) lua::setBoolean(L, "custom", true);
  return 1;
}

// pitwall.writeResults(rows, columns [, path]): rows (tables) as JSON or CSV, by the path's
// extension; the path defaults to --results.
int writeResults(lua_State* L) {
  if (!lua_istable(L, 1))
    throw LuaError("pitwall.writeResults: rows must be a list of tables, got " +
                   lua::typeName(L, 1));
  if (!lua_istable(L, 2))
    throw LuaError("pitwall.writeResults: columns must be a list of names, got " +
                   lua::typeName(L, 2));
  results::Table table;
  // The copy is bounded and charged to the world's cap (bindings/copy_budget.hpp): a results
  // file of a race is a few KB.
  lua::CopyBudget budget(L, "pitwall.writeResults", std::size_t{64} << 20);
  for (lua_Integer i = 1, n = luaL_len(L, 2); i <= n; ++i) {
    if (lua_geti(L, 2, i) != LUA_TSTRING)
      throw LuaError("pitwall.writeResults: column " + std::to_string(i) + " is not a name");
    table.columns.emplace_back(lua_tostring(L, -1));
    budget.add(table.columns.back().size() + 32, "column " + std::to_string(i));
    lua_pop(L, 1);
  }
  for (lua_Integer r = 1, n = luaL_len(L, 1); r <= n; ++r) {
    if (lua_geti(L, 1, r) != LUA_TTABLE)
      throw LuaError("pitwall.writeResults: row " + std::to_string(r) + " is not a table");
    auto& row = table.rows.emplace_back();
    for (const auto& column : table.columns) {
      int t = lua_getfield(L, -1, column.c_str());
      std::size_t length = 0;
      if (t == LUA_TSTRING) lua_tolstring(L, -1, &length);
      budget.add(length + 32, "row " + std::to_string(r));
      if (t == LUA_TNUMBER)
        row.emplace_back(static_cast<double>(lua_tonumber(L, -1)));
      else if (t == LUA_TSTRING)
        row.emplace_back(std::string(lua_tostring(L, -1)));
      else if (t == LUA_TBOOLEAN)
        row.emplace_back(lua_toboolean(L, -1) != 0);
      else if (t == LUA_TNIL)
        row.emplace_back(std::monostate{});
      else
        throw LuaError("pitwall.writeResults: row " + std::to_string(r) + ", " + column + ": a " +
                       luaL_typename(L, -1) + " cannot go in a results file");
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
  }
  std::string path = lua_isnoneornil(L, 3) ? ScriptHost::from(L).options().results
                                           : lua::checkString(L, 3, "results file");
  if (path.empty())
    throw LuaError("pitwall.writeResults: no file: run with --results FILE, or pass a path");
  if (auto written = results::write(path, table); !written) throw LuaError(written.error());
  lua_pushstring(L, path.c_str());
  return 1;
}

// pitwall.keepResults(race): a race's results ({kind, number, track, laps, entries}) into the
// standings database of the run (--db); true when written, false when the run keeps none, or
// false and the sentence when they were held or saved beside it (the race goes on either way).
int keepResults(lua_State* L) {
  luaL_checktype(L, 1, LUA_TTABLE);
  const auto& keep = ScriptHost::from(L).options().keepRace;
  if (!keep) {
    lua_pushboolean(L, 0);
    return 1;
  }
  lua::CopyBudget budget(L, "pitwall.keepResults", std::size_t{16} << 20);
  const nlohmann::json race =
      lua::toJson(L, 1, {"pitwall.keepResults", "the standings"}, budget, "race");
  const auto problem = keep(race);
  lua_pushboolean(L, problem ? 0 : 1);
  if (!problem) return 1;
  lua_pushlstring(L, problem->data(), problem->size());
  return 2;
}

// pitwall.terminal(): {tty = stdout is a terminal that a script may redraw (not while a REPL
// prompt is on it), columns = its width (COLUMNS, else 80)}.
int terminal(lua_State* L) {
  bool tty = ::isatty(STDOUT_FILENO) == 1 && !console::hasWriter();
  long columns = 0;
  winsize ws{};
  if (tty && ::ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0) columns = ws.ws_col;
  if (columns <= 0)
    if (const char* c = std::getenv("COLUMNS")) columns = std::strtol(c, nullptr, 10);
  if (columns <= 0) columns = 80;
  lua_createtable(L, 0, 3);
  lua::setBoolean(L, "tty", tty);
  lua::setInteger(L, "columns", columns);
  lua::setInteger(L, "output", static_cast<lua_Integer>(console::outputCount()));
  return 1;
}

const lua::TypeSpec& timerType() {
  static const luaL_Reg methods[] = {{"cancel", lua::guarded<cancelTimer>}, {nullptr, nullptr}};
  static const lua::TypeSpec type{
      .metatable = kTimerMetatable,
      .name = "timer",
      .methods = methods,
      .label =
          [](lua_State* L, int self) {
            return "timer " + std::to_string(lua::check<int>(L, self, timerType()));
          },
  };
  return type;
}

}  // namespace

void openPitwallModule(ScriptHost& host) {
  lua_State* L = host.state();
  lua::registerType(L, timerType());

  static const luaL_Reg functions[] = {{"cars", lua::guarded<cars>},
                                       {"car", lua::guarded<car>},
                                       {"now", now},
                                       {"after", lua::guarded<after>},
                                       {"every", lua::guarded<every>},
                                       {"cancel", lua::guarded<cancelTimer>},
                                       {"spawn", lua::guarded<spawn>},
                                       {"sleep", sleep},
                                       {"stop", stop},
                                       {"log", lua::guarded<logBody>},
                                       {"piece", lua::guarded<piece>},
                                       {"layout", lua::guarded<layout>},
                                       {"writeResults", lua::guarded<writeResults>},
                                       {"keepResults", lua::guarded<keepResults>},
                                       {"terminal", terminal},
                                       {"_setHub", lua::guarded<&lua::setHub>},
                                       {"_reportError", lua::guarded<reportError>},
                                       {"_traceback", lua::traceback},
                                       {"_raise", lua::guarded<raise>},
                                       {"_nearest", lua::guarded<nearestName>},
                                       {"_modulesIn", lua::guarded<modulesIn>},
                                       {"_checkOptions", lua::guarded<checkOptionsOf>},
                                       {nullptr, nullptr}};
  luaL_newlib(L, functions);
  lua_pushboolean(L, host.loop().clockKind() == ClockKind::Virtual);
  lua_setfield(L, -2, "virtualTime");
  lua_pushinteger(L, static_cast<lua_Integer>(host.options().seed));
  lua_setfield(L, -2, "seed");
  // What survives a hot reload (docs/hot-reload.md): the Reloader replaces this table with the
  // previous version's, copied, before the new version's main chunk runs.
  lua_newtable(L);
  lua_setfield(L, -2, "persist");
  lua_pushinteger(L, 0);
  lua_setfield(L, -2, "reloads");
  if (!host.options().results.empty()) {
    lua_pushstring(L, host.options().results.c_str());
    lua_setfield(L, -2, "resultsFile");
  }
  lua_pushvalue(L, -1);
  lua_setglobal(L, "pitwall");
  luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE);
  lua_pushvalue(L, -2);
  lua_setfield(L, -2, "pitwall");
  lua_pop(L, 2);
}

}  // namespace pitwall
