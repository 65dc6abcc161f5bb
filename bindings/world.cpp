#include "bindings/world.hpp"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "bindings/car_binding.hpp"
#include "bindings/interrupt.hpp"
#include "bindings/pitwall_module.hpp"
#include "bindings/sandbox.hpp"
#include "bindings/script_host.hpp"
#include "engine/core/console.hpp"
#include "engine/core/data_dir.hpp"

// What a world holds, in the order openWorld opens it:
//
//   Lua's libraries            luaL_openlibs, then sandbox::restrict (bindings/sandbox.hpp: text
//                              chunks only, a reading debug library, no finalizers, nothing that
//                              blocks the loop, the locked string and file metatables)
//   os.exit                    the run's stop path with an exit status (scriptExit)
//   coroutines, xpcall         the interrupt follows the thread that runs (bindings/interrupt.hpp)
//   require                    every module file found is recorded, for hot reload
//                              (searchAndRecord); its path: --lib folders, then the shipped
//                              library, then Lua's default; the script's own folder joins first
//                              when it is loaded (ScriptHost::loadFile)
//   print, io.write            to the console (above the REPL's prompt when there is one)
//   math.randomseed            the run's --seed: the same seed, the same numbers
//   the car type               pitwall.car (bindings/car_binding.cpp)
//   pitwall                    the module (bindings/pitwall_module.cpp): cars, time, timers
//                              (the timer type), tasks, stop, log, piece, layout, results
//   pitwall.stdout             a file-like object that writes to the console
//   pitwall.sim                with the simulator only (bindings/sim_binding.cpp), and on it
//                              sim.script / sim.reload (bindings/script_under_test.cpp)
//   pitwall.mindroad, .alphabot  the robots (bindings/mindroad_binding.cpp, alphabot_binding.cpp)
//   pitwall.view               what the race view shows (bindings/view_binding.cpp)
//   pitwall.seats, .seat       human drivers' seats (bindings/seat_binding.cpp); sim.openSeats
//   pitwall.driverFiles, _driverWorld  driver files in worlds of their own
//                              (bindings/driver_world_binding.cpp)
//   (a driver world: none of the six above, and no pitwall.writeResults or keepResults; its
//   Lua libraries read no file and require finds the shipped library only:
//   sandbox::restrictToLibrary)
//   the cars                   every car the fleet knows gets its Lua object now (later ones as
//                              they join: ScriptHost::carJoined)
//   the Lua library            require "pitwall.core" (scripts/pitwall/core.lua); in test mode
//                              also expect = require "pitwall.test"
//
// The private protocol (docs/architecture.md "The library's private protocol"): names on
// `pitwall` that begin with `_` are the engine's and the library's, not the script's.
//   made in C++, used by the library: _setHub, _reportError, _traceback, _raise, _nearest,
//     _modulesIn, _checkOptions (bindings/pitwall_module.cpp); sim._addCar (sim_binding.cpp)
//   made by the library, called from C++: _lastWords (ScriptHost::lastWords), _saveCarried and
//     _runHandover (a hot reload's hand-over, bindings/reloader.cpp); set from C++ for the
//     library: _carried (the previous version's carried data, reloader.cpp)
//   the library's own, between its modules: _carry, _takeCarried, _afterCarry, _atRunEnd,
//     _rethrow, _checkOptionsOf (scripts/pitwall/core.lua)

namespace pitwall {

namespace {

// The shipped library: $PITWALL_SCRIPTS (the tests' source tree), else scripts/ in the data
// folder found beside the binary (engine/core/data_dir.hpp).
std::string scriptsDir() {
  if (const char* env = std::getenv("PITWALL_SCRIPTS"); env && *env) return env;
  // found once a process: every world asks (a league race opens five), and the binary stays put
  static std::string found;
  if (found.empty()) {
    auto data = dataDir();
    if (!data) throw std::runtime_error(data.error());
    found = (*data / "scripts").string();
  }
  return found;
}

// print, io.write and pitwall.stdout:write go to the console: straight to stdout, or above the
// REPL's prompt. The values from `first` on: print's way (any value, tab-separated, a newline
// after), or io.write's (strings and numbers only, as they are).
int consoleWriteFrom(lua_State* L, int first, bool print = false) {
  const int n = lua_gettop(L);
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  for (int i = first; i <= n; ++i) {
    if (print || lua_type(L, i) == LUA_TNUMBER) {
      luaL_tolstring(L, i, nullptr);
    } else {
      luaL_checkstring(L, i);
      lua_pushvalue(L, i);
    }
    luaL_addvalue(&b);
    if (print) luaL_addchar(&b, i < n ? '\t' : '\n');
  }
  if (print && n < first) luaL_addchar(&b, '\n');
  luaL_pushresult(&b);
  size_t len = 0;
  const char* text = lua_tolstring(L, -1, &len);
  console::write({text, len});
  return 0;
}

int consolePrint(lua_State* L) {
  return consoleWriteFrom(L, 1, true);
}

int consoleIoWrite(lua_State* L) {
  consoleWriteFrom(L, 1);
  lua_getglobal(L, "io");  // io.write returns the file it wrote to
  lua_getfield(L, -1, "stdout");
  return 1;
}

int consoleFileWrite(lua_State* L) {
  consoleWriteFrom(L, 2);
  lua_settop(L, 1);
  return 1;
}

int consoleFileFlush(lua_State* L) {
  lua_settop(L, 1);
  return 1;
}

// os.exit([code]): the run ends through the engine's stop path (the cars get their stop, the
// record is flushed) with this exit status; the code running now is ended like an interrupt.
int scriptExit(lua_State* L) {
  int status = EXIT_SUCCESS;
  if (lua_isboolean(L, 1))
    status = lua_toboolean(L, 1) ? EXIT_SUCCESS : EXIT_FAILURE;
  else if (!lua_isnoneornil(L, 1))
    status = static_cast<int>(luaL_checkinteger(L, 1) & 0xff);
  ScriptHost::from(L).requestExit(status);
  interrupt::abortRunning("os.exit: the run is ending");
  return 0;
}

// require's Lua-file searcher, wrapped: every module file it finds is recorded, so that a hot
// reload watches the modules of a script as well as the script.
int searchAndRecord(lua_State* L) {
  lua_settop(L, 1);
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, 1, 2);
  if (lua_isfunction(L, 1) && lua_type(L, 2) == LUA_TSTRING) {
    std::error_code ignored;
    ScriptHost::from(L).fileLoaded(
        std::filesystem::absolute(lua_tostring(L, 2), ignored).lexically_normal().string());
  }
  return 2;
}

void openLuaLibraries(lua_State* L) {
  luaL_openlibs(L);
  sandbox::restrict(L);
  lua_getglobal(L, "os");
  lua_pushcfunction(L, scriptExit);
  lua_setfield(L, -2, "exit");
  lua_pop(L, 1);
  interrupt::openCoroutineTracking(L);
  lua_getglobal(L, "package");
  lua_getfield(L, -1, "searchers");
  lua_rawgeti(L, -1, 2);
  lua_pushcclosure(L, searchAndRecord, 1);
  lua_rawseti(L, -2, 2);
  lua_pop(L, 2);
}

void openConsole(lua_State* L) {
  lua_pushcfunction(L, consolePrint);
  lua_setglobal(L, "print");
  lua_getglobal(L, "io");
  lua_pushcfunction(L, consoleIoWrite);
  lua_setfield(L, -2, "write");
  lua_pop(L, 1);
}

void seedRandom(lua_State* L, std::uint64_t seed) {
  lua_getglobal(L, "math");
  lua_getfield(L, -1, "randomseed");
  lua_pushinteger(L, static_cast<lua_Integer>(seed));
  lua_call(L, 1, 0);
  lua_pop(L, 1);
}

void openStdout(lua_State* L) {
  lua_getglobal(L, "pitwall");
  lua_createtable(L, 0, 2);
  lua_pushcfunction(L, consoleFileWrite);
  lua_setfield(L, -2, "write");
  lua_pushcfunction(L, consoleFileFlush);
  lua_setfield(L, -2, "flush");
  lua_setfield(L, -2, "stdout");
  lua_pop(L, 1);
}

// The Lua half of the module (waitUntil, copy, …) and, in tests, the expectations.
// A driver world's `pitwall` (docs/drivers.md): no results file; the rest reads or is its own.
void closeForDrivers(lua_State* L) {
  lua_getglobal(L, "pitwall");
  lua_pushnil(L);
  lua_setfield(L, -2, "writeResults");
  lua_pushnil(L);
  lua_setfield(L, -2, "keepResults");
  lua_pop(L, 1);
}

void openLuaLibrary(ScriptHost& host, const std::string& lib) {
  lua_State* L = host.state();
  const char* prelude = host.options().test_mode
                            ? "require 'pitwall.core'; expect = require 'pitwall.test'"
                            : "require 'pitwall.core'";
  std::string err;
  if (luaL_loadstring(L, prelude) != LUA_OK) {
    err = lua_tostring(L, -1);
    lua_pop(L, 1);
  } else {
    host.callLibrary(0, 0, err);  // a budget of its own: a library that never loads fails too
  }
  if (!err.empty())
    throw std::runtime_error("cannot load the pitwall Lua library from " + lib + ": " + err +
                             " (set PITWALL_SCRIPTS to the folder that holds pitwall/core.lua)");
}

}  // namespace

void prependRequirePath(lua_State* L, const std::vector<std::string>& dirs) {
  std::string path;
  for (const auto& dir : dirs) path += dir + "/?.lua;" + dir + "/?/init.lua;";
  lua_getglobal(L, "package");
  lua_getfield(L, -1, "path");
  path += lua_tostring(L, -1);
  lua_pop(L, 1);
  lua_pushlstring(L, path.data(), path.size());
  lua_setfield(L, -2, "path");
  lua_pop(L, 1);
}

void compileLibraryAhead() {
  namespace fs = std::filesystem;
  const std::string lib = scriptsDir();
  std::vector<std::string> files;
  std::error_code ec;
  for (fs::recursive_directory_iterator
           it(lib, fs::directory_options::follow_directory_symlink, ec),
       end;
       !ec && it != end; it.increment(ec)) {
    // (the name require finds it by: the folder as given, then the path inside it)
    if (it->path().extension() == ".lua" && it->is_regular_file(ec))
      files.push_back(lib + "/" + it->path().lexically_relative(lib).generic_string());
  }
  sandbox::compileAhead(files);
}

void openWorld(ScriptHost& host) {
  lua_State* L = host.state();
  const std::string lib = scriptsDir();
  openLuaLibraries(L);
  openConsole(L);
  // require: the --lib folders first, then the shipped library, then Lua's default
  std::vector<std::string> dirs = host.options().library_paths;
  dirs.push_back(lib);
  prependRequirePath(L, dirs);
  const bool driver = host.driverCar() != nullptr;
  if (driver) sandbox::restrictToLibrary(L, lib + "/?.lua;" + lib + "/?/init.lua");
  host.setLibrary(lib);  // its chunks' names, for the blame (lua::Frames)
  seedRandom(L, host.options().seed);
  host.cars().registerType(L);
  openPitwallModule(host);
  openStdout(L);
  if (driver) {
    closeForDrivers(L);
  } else {
    if (host.sim()) openSimModule(host);
    openMindroadModule(host);
    openAlphabotModule(host);
    openViewModule(host);
    openSeatModule(host);
    openDriverWorlds(host);
    openClassroomModule(host);
  }
  for (AnkiCar* car : host.fleet().cars()) host.cars().bind(*car);
  openLuaLibrary(host, lib);
}

}  // namespace pitwall
