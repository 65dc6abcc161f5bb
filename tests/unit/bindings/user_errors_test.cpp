// Errors that point at the user (issue 18), where a scenario cannot reach: the REPL's way into
// Lua, the option checker's hostile inputs, and script files named relative to the current
// folder. tests/scenarios/user_errors_test.lua checks the library's errors line by line.
#include <doctest/doctest.h>

#include <array>
#include <filesystem>
#include <fstream>

#include "bindings/lua_args.hpp"
#include "bindings/lua_options.hpp"
#include "bindings/misspelled_method.hpp"
#include "bindings/script_file.hpp"
#include "bindings/script_host.hpp"
#include "tests/unit/capture_link.hpp"

using namespace pitwall;
using pitwall::testing::CaptureLink;

namespace {

struct Host {
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  std::unique_ptr<ScriptHost> host;
  Host() {
    auto l = std::make_unique<CaptureLink>();
    CaptureLink* link = l.get();
    fleet.add(std::move(l), CarIdentity{0, "skull", 9, 1});
    link->setConnected(true);
    setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
    host = std::make_unique<ScriptHost>(loop, fleet, nullptr, HostOptions{});
  }
  // A chunk as the REPL runs it (ScriptHost::callInteractive); its error, or "".
  std::string repl(const std::string& code) {
    lua_State* L = host->state();
    if (luaL_loadbufferx(L, code.data(), code.size(), "=stdin", "t") != LUA_OK) {
      std::string e = lua_tostring(L, -1);
      lua_pop(L, 1);
      return e;
    }
    std::string error;
    return host->callInteractive(0, 0, error) ? "" : error;
  }
};

int checkKeys(lua_State* L) {
  static constexpr std::array<const char*, 2> kKnown = {"laps", "minutes"};
  try {
    lua::checkOptions(L, 1, "race.laps", kKnown);
  } catch (const lua::LuaError& e) {
    lua_pushstring(L, e.what());
    return 1;
  }
  lua_pushnil(L);
  return 1;
}

}  // namespace

TEST_CASE_FIXTURE(Host, "at the REPL a misspelled method names the type and the nearest method") {
  std::string err = repl("local car = pitwall.cars()[1]\ncar:setSped(300)");
  CHECK(err.rfind("stdin:2: car has no method setSped; did you mean setSpeed?\n", 0) == 0);
  // an argument that is nil before an object does not mislead it
  err = repl(
      "local t = setmetatable({}, {__name = 'thing', __index = {go = print}})\n"
      "t:og(nil, pitwall.cars()[1])");
  CHECK(err.rfind("stdin:2: thing has no method og; did you mean go?", 0) == 0);
  // a nil and a car before the call do not mislead it either: the call's own object is named,
  // and never a type that has the method
  err = repl(
      "local car = pitwall.cars()[1]\n"
      "local t = setmetatable({}, {__name = 'thing', __index = {wave = print}})\n"
      "print(car.nosuchfield, car, t:wvae())");
  CHECK(err.rfind("stdin:3: thing has no method wvae; did you mean wave?", 0) == 0);
  err = repl(
      "local car = pitwall.cars()[1]\nlocal t = {}\nprint(car.nosuchfield, car, t:setSpeed(1))");
  CHECK(err.find("car has no method") == std::string::npos);
  CHECK(err.find("attempt to call a nil value (method 'setSpeed')") != std::string::npos);
  // a case-only slip gets the method in its case
  err = repl("local car = pitwall.cars()[1]\ncar:SetSpeed(300)");
  CHECK(err.rfind("stdin:2: car has no method SetSpeed; did you mean setSpeed?", 0) == 0);
  // the handler runs nothing of the script's: a metatable whose __index raises or never returns
  // (a "strict" guard) keeps Lua's own message, and the run goes on
  for (const char* guard : {"error('strict: ' .. k)", "while true do end"}) {
    err = repl(std::string("local mt = setmetatable({}, {__index = function(_, k) ") + guard +
               " end})\nlocal o = setmetatable({}, mt)\no:og()");
    CHECK(err.rfind("stdin:3: attempt to call a nil value (method 'og')", 0) == 0);
  }
  // a table without methods, or a call of a nil field, keeps Lua's own words
  CHECK(repl("local t = {}\nt:go()").find("attempt to call a nil value (method 'go')") !=
        std::string::npos);
  CHECK(repl("local car = pitwall.cars()[1]\ncar.setSped(car, 1)")
            .find("attempt to call a nil value (field 'setSped')") != std::string::npos);
  // reading a missing name stays nil: a script's own fields work as in plain Lua
  CHECK(repl("local car = pitwall.cars()[1]\nassert(car.setSped == nil and not car.mine)") == "");
}

TEST_CASE_FIXTURE(Host, "at the REPL the typos of issue 35 name what exists and the nearest") {
  // a library function: the table as the chunk names it
  CHECK(repl("pitwall.spwan(print)")
            .rfind("stdin:1: pitwall has no function spwan; did you mean pitwall.spawn?\n", 0) ==
        0);
  CHECK(repl("local pw = require 'pitwall'\npw.evrey(1, print)")
            .rfind("stdin:2: pw has no function evrey; did you mean pw.every?", 0) == 0);
  CHECK(repl("pitwall.view.evnt('x')")
            .rfind("stdin:1: pitwall.view has no function evnt; did you mean pitwall.view.event?",
                   0) == 0);
  // a car by name or number
  CHECK(repl("pitwall.car('skul'):setSpeed(500)")
            .rfind("stdin:1: pitwall.car: no car named 'skul'; did you mean skull? The only car "
                   "is 1 skull\n",
                   0) == 0);
  CHECK(repl("pitwall.car(9)")
            .rfind("stdin:1: pitwall.car: no car 9; the only car is 1 skull\n", 0) == 0);
  // a car of a list of cars: the REPL's global `cars` by its name, another list as a list
  CHECK(repl("cars = pitwall.cars()\ncars[9]:setSpeed(500)")
            .rfind("stdin:2: cars[9] is nil: there is no car 9; the only car is 1 skull\n", 0) ==
        0);
  CHECK(repl("local mine = pitwall.cars()\nprint(mine[2].speed)")
            .rfind("stdin:2: this list of cars has no [2]; it holds 1 skull\n", 0) == 0);
  // plain Lua stays: a test for a car that is not there, ipairs, and a later nil of another table
  CHECK(
      repl("local n = 0\nfor _ in ipairs(cars) do n = n + 1 end\nassert(n == 1 and not cars[2])") ==
      "");
  std::string err = repl("local x = cars[5]\nlocal t = {}\nprint(t[1].y)");
  CHECK(err.rfind("stdin:3: attempt to index a nil value (field '", 0) == 0);
  // a list's metatable is the engine's, locked: a script cannot replace its __index
  err = repl("local l = pitwall.cars()\ngetmetatable(l).__index = function() error('mine') end");
  CHECK(err.find("cannot set __index on the metatable of car list") != std::string::npos);
  CHECK(repl("local l = pitwall.cars()\nprint(l[1]:nosuch())").find("car has no method nosuch") !=
        std::string::npos);
}

TEST_CASE("a message that is not a missing name is left alone") {
  lua_State* L = luaL_newstate();
  CHECK_FALSE(lua::explainMissingMethod(L, 0, "x.lua:1: boom"));
  CHECK_FALSE(lua::explainMissingMethod(L, 0, "attempt to call a nil value (method 'go"));
  CHECK_FALSE(lua::explainMissingName(L, 0, "x.lua:1: boom"));
  CHECK_FALSE(lua::explainMissingName(L, 0, "attempt to call a nil value (field 'go"));
  CHECK_FALSE(
      lua::explainMissingName(L, 0, "attempt to index a nil value (field 'integer index')"));
  CHECK_FALSE(lua::explainMissingName(L, 0, "attempt to index a nil value (field '?"));
  lua_close(L);
}

TEST_CASE("the option checker refuses hostile keys with a clear error and never crashes") {
  lua_State* L = luaL_newstate();
  luaL_openlibs(L);
  lua_register(L, "check", checkKeys);
  auto run = [L](const char* code) {
    REQUIRE(luaL_dostring(L, code) == LUA_OK);
    std::string out = lua_isnil(L, -1) ? "" : lua_tostring(L, -1);
    lua_settop(L, 0);
    return out;
  };
  CHECK(run("return check{laps = 3, minutes = 2}") == "");
  CHECK(run("return check(42)") == "");  // not a table: the caller's own check says so
  CHECK(run("return check{[''] = 1}") ==
        "race.laps: unknown option \"\" (an empty name) (the options are laps, minutes)");
  CHECK(run("return check{Laps = 3}") ==
        "race.laps: unknown option Laps; did you mean laps? (the options are laps, minutes)");
  CHECK(run("return check{lapz = 3}") ==
        "race.laps: unknown option lapz; did you mean laps? (the options are laps, minutes)");
  CHECK(run("return check{3}") ==
        "race.laps: option names are strings, got the number key 1 (a list where the options "
        "go?) (the options are laps, minutes)");
  CHECK(run("return check{[0/0 ~= 0/0] = 1}") ==
        "race.laps: option names are strings, got the boolean key true (the options are laps, "
        "minutes)");
  CHECK(run("return check{[print] = 1}").find("got a function key") != std::string::npos);
  CHECK(run("return check{['\\0\\xff\\n'] = 1}") ==
        "race.laps: unknown option \\x00\\xff\\x0a (the options are laps, minutes)");
  CHECK(run("return check{['vitésse'] = 1}") ==
        "race.laps: unknown option vitésse (the options are laps, minutes)");
  CHECK(run("return check{['\\xe9t\\xc3'] = 1}") ==  // Latin-1, a cut character
        "race.laps: unknown option \\xe9t\\xc3 (the options are laps, minutes)");
  std::string huge = run("return check{[string.rep('é', 500000)] = 1}");
  CHECK(huge.size() < 400);
  CHECK(huge.find("… (1000000 bytes)") != std::string::npos);
  CHECK(run("local t = {} for i = 1, 200000 do t[i] = i end return check(t)").find("number key") !=
        std::string::npos);
  lua_close(L);
}

TEST_CASE("a script's file is named relative to the current folder when it is inside it") {
  namespace fs = std::filesystem;
  const fs::path here = fs::current_path();
  CHECK(script_file::shownPath((here / "examples" / "lap.lua").string()) == "examples/lap.lua");
  CHECK(script_file::shownPath("./examples/../lap.lua") == "lap.lua");
  CHECK(script_file::shownPath("/nonexistent-pitwall/lap.lua") == "/nonexistent-pitwall/lap.lua");

  const fs::path dir = fs::temp_directory_path() / "pitwall-script-file-test";
  fs::create_directories(dir);
  std::ofstream(dir / "shebang.lua") << "#!/usr/bin/env pitwall run\nlocal x = \nfor\n";
  auto problem = script_file::check((dir / "shebang.lua").string());
  REQUIRE(problem);
  CHECK(problem->find("shebang.lua:3:") != std::string::npos);  // the first line still counts
  auto missing = script_file::check((dir / "nosuch.lua").string());
  REQUIRE(missing);
  CHECK(missing->find("cannot open ") == 0);
  CHECK(missing->find("nosuch.lua: no such file") != std::string::npos);
  CHECK(script_file::check(dir.string())->find("it is a folder") != std::string::npos);
  std::ofstream(dir / "fine.lua") << "return 1\n";
  CHECK_FALSE(script_file::check((dir / "fine.lua").string()));
  fs::remove_all(dir);
}
