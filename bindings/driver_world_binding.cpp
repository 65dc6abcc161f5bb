// Driver worlds as the run's world sees them (docs/drivers.md): pitwall.driverFiles (and a
// league final's pitwall.final, docs/league.md), the
// --driver CAR=FILE of the command line, and pitwall._driverWorld(file, car), the engine's half
// of drivers.world (scripts/pitwall/drivers.lua), which a race director calls like any driver.
// A driver world object: world:call(method, …) → true, or false once the world has failed (the
// values after the method are copied into the world: drivers.lua's send, driver_world.lua's call);
// world:reload() → true when the new world loaded; world:tryReload() → true, or false and why
// (the world driving goes on: a new one replaces it only when it loads); world:close() ends it
// for good (its session
// ended); fields failure (why it is out, nil while it
// drives), file, version (1, +1 a reload), cpu (s its calls used).
#include <filesystem>
#include <memory>

#include "bindings/car_binding.hpp"
#include "bindings/driver_world.hpp"
#include "bindings/lua_args.hpp"
#include "bindings/lua_object.hpp"
#include "bindings/pitwall_module.hpp"
#include "bindings/script_file.hpp"
#include "bindings/script_host.hpp"

namespace pitwall {

namespace {

using lua::LuaError;

constexpr const char* kMetatable = "pitwall.driverworld";

const lua::TypeSpec& worldType();

using Box = std::unique_ptr<DriverWorld>;

DriverWorld& worldAt(lua_State* L, int idx) {
  Box& box = lua::check<Box>(L, idx, worldType());
  if (!box) throw LuaError("this driver world is gone");
  return *box;
}

int call(lua_State* L) {
  DriverWorld& w = worldAt(L, 1);
  const char* method = luaL_checkstring(L, 2);
  const bool ok = w.call(L, method, 3);
  lua_pushboolean(L, ok);
  return 1;
}

int reload(lua_State* L) {
  lua_pushboolean(L, worldAt(L, 1).reload());
  return 1;
}

int tryReload(lua_State* L) {
  std::string why;
  if (worldAt(L, 1).tryReload(why)) {
    lua_pushboolean(L, 1);
    return 1;
  }
  lua_pushboolean(L, 0);
  lua_pushlstring(L, why.data(), why.size());
  return 2;
}

int close(lua_State* L) {
  worldAt(L, 1).close();
  return 0;
}

void pushText(lua_State* L, const std::string& s) {
  lua_pushlstring(L, s.data(), s.size());
}

const lua::Field kFields[] = {
    {"failure",
     [](lua_State* L, int self) {
       const std::string& why = worldAt(L, self).failure();
       if (why.empty())
         lua_pushnil(L);
       else
         pushText(L, why);
     }},
    {"file", [](lua_State* L, int self) { pushText(L, worldAt(L, self).file()); }},
    {"version", [](lua_State* L, int self) { lua_pushinteger(L, worldAt(L, self).version()); }},
    {"cpu", [](lua_State* L, int self) { lua_pushnumber(L, worldAt(L, self).cpuSeconds()); }},
};

const lua::TypeSpec& worldType() {
  static const luaL_Reg methods[] = {{"call", lua::guarded<call>},
                                     {"reload", lua::guarded<reload>},
                                     {"tryReload", lua::guarded<tryReload>},
                                     {"close", lua::guarded<close>},
                                     {nullptr, nullptr}};
  static const lua::TypeSpec type{
      .metatable = kMetatable,
      .name = "driver world",
      .methods = methods,
      .fields = kFields,
      .strict = true,
      .label =
          [](lua_State* L, int self) {
            DriverWorld& w = worldAt(L, self);
            return "driver world " + std::filesystem::path(w.file()).filename().string() + " of " +
                   w.car().label();
          },
      .gc = [](lua_State* L, int self) { lua::destroyBox<Box>(L, self, worldType()); },
  };
  return type;
}

// pitwall._driverWorld(file, car): a driver world for `car` from `file`, with the run's
// DriverLimits. A file that cannot be read is the caller's error; one that does not load or
// fails makes a world that is out (its failure says why), as a broken save does.
int newWorld(lua_State* L) {
  std::string file = lua::checkString(L, 1, "driver file");
  AnkiCar& car = CarBinding::check(L, 2);
  ScriptHost& host = ScriptHost::from(L);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    throw LuaError("driver file " + file +
                   ": no such file (a driver is a Lua file that returns "
                   "a driver, docs/drivers.md)");
  file = std::filesystem::absolute(file, ec).lexically_normal().string();
  lua::newBox<Box>(L, worldType(),
                   std::make_unique<DriverWorld>(host, car, file, host.options().driverLimits));
  return 1;
}

}  // namespace

void openDriverWorlds(ScriptHost& host) {
  lua_State* L = host.state();
  lua::registerType(L, worldType());
  lua_getglobal(L, "pitwall");
  lua_pushcfunction(L, lua::guarded<newWorld>);
  lua_setfield(L, -2, "_driverWorld");
  lua_createtable(L, 0, static_cast<int>(host.options().driverFiles.size()));
  for (const auto& [number, file] : host.options().driverFiles) {
    pushText(L, file);
    lua_rawseti(L, -2, number);
  }
  lua_setfield(L, -2, "driverFiles");
  if (const auto& final = host.options().leagueFinal) {
    lua_createtable(L, 0, 4);
    pushText(L, final->title);
    lua_setfield(L, -2, "title");
    lua_pushinteger(L, final->laps);
    lua_setfield(L, -2, "laps");
    lua_pushinteger(L, static_cast<lua_Integer>(final->league));
    lua_setfield(L, -2, "league");
    lua_createtable(L, static_cast<int>(final->drivers.size()), 0);
    for (std::size_t i = 0; i < final->drivers.size(); ++i) {
      pushText(L, final->drivers[i]);
      lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
    }
    lua_setfield(L, -2, "drivers");
    lua_setfield(L, -2, "final");
  }
  lua_pop(L, 1);
}

}  // namespace pitwall
