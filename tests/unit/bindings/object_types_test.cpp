// The LuaLS definitions (scripts/pitwall/types.lua) against the binding's own metadata: every
// registered object type is seen, and a method, field, event or function that the binary has
// and the annotations do not — or the other way round — stops the generator, named.
#include "bindings/object_types.hpp"

#include <doctest/doctest.h>

#include <memory>
#include <string>

#include "bindings/script_host.hpp"
#include "engine/sim/track.hpp"
#include "engine/sim/world.hpp"

using namespace pitwall;

namespace {

struct TypesFixture {
  Loop loop{ClockKind::Virtual};
  SimSession sim;
  Fleet fleet{loop};
  std::unique_ptr<ScriptHost> host;

  TypesFixture() {
    setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
    sim.world = std::make_unique<sim::World>(loop, *sim::namedLayout("oval"), 1);
    HostOptions options;
    options.test_mode = true;  // `expect`, as in `pitwall test` and `pitwall types`
    host = std::make_unique<ScriptHost>(loop, fleet, &sim, options);
  }

  // Runs `change` (a chunk given the object types as `types`; it may change them or the world),
  // then the generator. Returns "ok: " and the text of `file`, or "error: " and the message.
  std::string generate(const std::string& change, const std::string& file = "pitwall.lua") {
    lua_State* L = host->state();
    const std::string code = "local types = ...\n" + change +
                             "\nlocal ok, out = pcall(require('pitwall.types').generate, types)\n"
                             "if not ok then return 'error: ' .. tostring(out) end\n"
                             "return 'ok: ' .. tostring(out['" +
                             file + "'])";
    REQUIRE(luaL_loadstring(L, code.c_str()) == LUA_OK);
    lua::pushObjectTypes(L);
    REQUIRE_MESSAGE(lua_pcall(L, 1, 1, 0) == LUA_OK, lua_tostring(L, -1));
    std::string result = lua_tostring(L, -1);
    lua_pop(L, 1);
    return result;
  }
};

// A copy of the car's metatable whose list `key` is changed by `edit` (Lua statements on `t`).
std::string editCar(const std::string& key, const std::string& edit) {
  return "local mt = {}\n"
         "for k, v in pairs(types['pitwall.car']) do mt[k] = v end\n"
         "local t = {}\n"
         "for k, v in pairs(mt." +
         key + ") do t[k] = v end\n" + edit + "\nmt." + key +
         " = t\n"
         "types['pitwall.car'] = mt\n";
}

}  // namespace

TEST_CASE_FIXTURE(TypesFixture, "types: every registered object type reaches the generator") {
  lua_State* L = host->state();
  lua::pushObjectTypes(L);
  for (const char* key : {"pitwall.car", "pitwall.mindroad", "pitwall.alphabot", "pitwall.timer"}) {
    CAPTURE(key);
    CHECK(lua_getfield(L, -1, key) == LUA_TTABLE);
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
}

TEST_CASE_FIXTURE(TypesFixture,
                  "types: the definitions hold the car's methods, fields and events as the binary "
                  "registered them") {
  const std::string out = generate("");
  REQUIRE(out.rfind("ok: ", 0) == 0);
  CHECK(out.find("---@meta") != std::string::npos);
  CHECK(out.find("function Car:setSpeed(speed, accel, respectLimit) end") != std::string::npos);
  CHECK(out.find("---@field onPosition? fun(car: pitwall.Car, e: pitwall.PositionEvent)") !=
        std::string::npos);
  CHECK(out.find("---@field batteryLevel integer?") != std::string::npos);
  CHECK(out.find("function Mindroad:steer(x, y) end") != std::string::npos);
  CHECK(out.find("---@field onLost? fun(robot: pitwall.Mindroad, reason: string)") !=
        std::string::npos);
  CHECK(out.find("function pitwall.after(delay, fn) end") != std::string::npos);
  CHECK(out.find("function pitwall.sim.addCar(spec) end") != std::string::npos);
  CHECK(out.find("function expect.eq(actual, expected, what) end") != std::string::npos);
  const std::string race = generate("", "pitwall/race.lua");
  CHECK(race.find("function race.laps(options) end") != std::string::npos);
  CHECK(race.find("---@field falseStartPenalty? number") != std::string::npos);
}

TEST_CASE_FIXTURE(TypesFixture, "types: a method added to the binary without annotation is named") {
  const std::string out = generate(editCar("__methods", "t.fly = print"));
  CHECK(out.rfind("error: ", 0) == 0);
  CHECK(out.find("pitwall.Car method fly exists in the binary but has no annotation") !=
        std::string::npos);
}

TEST_CASE_FIXTURE(TypesFixture, "types: a method removed from the binary is named") {
  const std::string out = generate(editCar("__methods", "t.setSpeed = nil"));
  CHECK(out.find("pitwall.Car method setSpeed is annotated but no longer exists") !=
        std::string::npos);
}

TEST_CASE_FIXTURE(TypesFixture, "types: a field or event added to the binary is named") {
  CHECK(generate(editCar("__fields", "t[#t + 1] = 'altitude'"))
            .find("pitwall.Car field altitude exists in the binary but has no annotation") !=
        std::string::npos);
  CHECK(generate(editCar("__events", "t[#t + 1] = 'onJump'"))
            .find("pitwall.Car event onJump exists in the binary but has no annotation") !=
        std::string::npos);
}

TEST_CASE_FIXTURE(TypesFixture, "types: an object type registered without annotation is named") {
  const std::string out =
      generate("types['pitwall.hovercraft'] = {__methods = {}, __fields = {}, __events = {}}");
  CHECK(out.find("object type pitwall.hovercraft is registered but has no annotation") !=
        std::string::npos);
}

TEST_CASE_FIXTURE(TypesFixture,
                  "types: a pitwall function or a library function without annotation is named") {
  CHECK(generate("pitwall.teleport = function() end")
            .find("pitwall function teleport exists in the binary but has no annotation") !=
        std::string::npos);
  CHECK(generate("pitwall.sim.rain = function() end")
            .find("pitwall.sim function rain exists in the binary but has no annotation") !=
        std::string::npos);
  CHECK(generate("require('pitwall.race').sprint = function() end")
            .find("pitwall.race function sprint exists in the binary but has no annotation") !=
        std::string::npos);
  CHECK(generate("pitwall.piece = nil")
            .find("pitwall function piece is annotated but no longer exists") != std::string::npos);
}

TEST_CASE_FIXTURE(TypesFixture, "types: every definition file is Lua that compiles") {
  lua_State* L = host->state();
  const char* code = R"(
    local out = require('pitwall.types').generate(...)
    local n = 0
    for name, text in pairs(out) do
      assert(load(text, '=' .. name, 't'))
      assert(text:match('^%-%-%-@meta'), name .. ' has no ---@meta')
      n = n + 1
    end
    return n)";
  REQUIRE(luaL_loadstring(L, code) == LUA_OK);
  lua::pushObjectTypes(L);
  REQUIRE_MESSAGE(lua_pcall(L, 1, 1, 0) == LUA_OK, lua_tostring(L, -1));
  CHECK(lua_tointeger(L, -1) == 14);  // pitwall.lua and one file per module under pitwall/
  lua_pop(L, 1);
}
