// The script's side of the stop path and of the sandbox (docs/safety.md): a world that was shut
// down runs nothing again, os.exit asks for the end of the run, and the memory cap ends a script
// that keeps allocating, even behind pcall.
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "bindings/interrupt.hpp"
#include "bindings/sandbox.hpp"
#include "bindings/script_host.hpp"
#include "engine/core/log.hpp"

using namespace pitwall;
using namespace std::chrono_literals;

namespace {

struct World {
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  std::unique_ptr<ScriptHost> host;
  std::vector<std::string> logged;
  int stops = 0;

  explicit World(std::size_t memoryLimit = sandbox::kDefaultMemoryLimit,
                 std::chrono::milliseconds budget = interrupt::kDefaultBudget) {
    setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
    HostOptions options;
    options.memory_limit = memoryLimit;
    options.budget = budget;
    host = std::make_unique<ScriptHost>(loop, fleet, nullptr, options);
    host->onStopRequested = [this] { ++stops; };
    log::setSink([this](log::Level, std::string_view line) { logged.emplace_back(line); });
  }
  ~World() { log::setSink(nullptr); }

  lua_Integer global(const char* name) {
    lua_getglobal(host->state(), name);
    lua_Integer v = lua_tointeger(host->state(), -1);
    lua_pop(host->state(), 1);
    return v;
  }
  bool logContains(const std::string& text) const {
    for (const auto& l : logged)
      if (l.find(text) != std::string::npos) return true;
    return false;
  }
};

}  // namespace

TEST_CASE("a world that was shut down runs no timer, task or callback again") {
  World w;
  REQUIRE(w.host->startString(R"(
    ticks, after, woke = 0, 0, 0
    pitwall.every(0.1, function() ticks = ticks + 1 end)
    pitwall.after(1, function() after = after + 1 end)
    pitwall.spawn(function() pitwall.sleep(0.5) woke = woke + 1 end)
    function late() pitwall.after(0, function() after = after + 100 end) end
  )",
                              "world"));
  w.loop.after(250ms, [&] {
    w.host->shutDown();
    w.loop.after(5s, [&] { w.loop.stop(); });
  });
  w.loop.run();
  CHECK(w.global("ticks") == 2);
  CHECK(w.global("after") == 0);
  CHECK(w.global("woke") == 0);
  CHECK(w.host->isShutDown());

  // The engine's calls into it are turned away with the stack left as it was.
  lua_State* L = w.host->state();
  int top = lua_gettop(L);
  lua_getglobal(L, "late");
  lua_pushinteger(L, 1);
  CHECK_FALSE(w.host->call(1, 0, "test callback"));
  CHECK(lua_gettop(L) == top);
  // A REPL chunk still runs (the operator may look), but what it schedules never fires.
  lua_getglobal(L, "late");
  std::string error;
  CHECK(w.host->callInteractive(0, 0, error));
  w.loop.after(1s, [&] { w.loop.stop(); });
  w.loop.run();
  CHECK(w.global("after") == 0);
}

TEST_CASE("os.exit asks for the end of the run with its status, even inside pcall") {
  World w;
  REQUIRE(w.host->startString(R"(
    pitwall.spawn(function()
      pitwall.sleep(1)
      pcall(os.exit, 7)
      reached = 1
    end)
  )",
                              "exit"));
  w.loop.after(10s, [&] { w.loop.stop(); });
  w.loop.run();
  REQUIRE(w.host->exitStatus());
  CHECK(*w.host->exitStatus() == 7);
  CHECK(w.stops == 1);
  CHECK(w.global("reached") == 0);   // the code after it did not run
  CHECK(w.host->errorCount() == 0);  // and nothing was reported as an error
}

TEST_CASE("os.exit's status: none and true are 0, false is 1") {
  for (auto [code, status] : {std::pair{"os.exit()", 0}, std::pair{"os.exit(true)", 0},
                              std::pair{"os.exit(false)", 1}, std::pair{"os.exit(300)", 44}}) {
    World w;
    REQUIRE(w.host->startString(code, "exit"));
    REQUIRE(w.host->exitStatus());
    CHECK(*w.host->exitStatus() == status);
  }
}

TEST_CASE("an allocation loop behind pcall reaches the memory cap and the run ends") {
  World w(std::size_t{16} << 20, 0ms);  // only the cap may end it
  auto started = w.host->startString(R"(
    local keep = {}
    while true do
      pcall(function() keep[#keep + 1] = string.rep("x", 1 << 20) .. #keep end)
    end
  )",
                                     "hog");
  REQUIRE(started);
  REQUIRE(w.host->exitStatus());
  CHECK(*w.host->exitStatus() == 1);
  CHECK(w.stops == 1);
  CHECK(w.host->memory().exceeded);
  CHECK(w.host->memory().used <= (std::size_t{16} << 20) + (std::size_t{4} << 20));
  CHECK(w.logContains("script memory limit of 16 MB reached"));
}

TEST_CASE("memory under the cap is served, and what is freed counts no more") {
  World w(std::size_t{16} << 20, 0ms);  // twenty full collections take their time under load
  auto started = w.host->startString(R"(
    for round = 1, 20 do
      local t = {}
      for i = 1, 8 do t[i] = string.rep("y", 1 << 20) .. i end
      t = nil
      collectgarbage()
    end
    done = 1
  )",
                                     "churn");
  REQUIRE(started);
  CHECK(w.global("done") == 1);
  CHECK_FALSE(w.host->memory().exceeded);
  CHECK_FALSE(w.host->exitStatus());
}

TEST_CASE("os.exit inside a coroutine is not caught by a pcall around the coroutine") {
  World w;
  REQUIRE(w.host->startString(R"(
    local co = coroutine.wrap(function() os.exit(4) end)
    print(pcall(co))
    reached = 1
  )",
                              "exit"));
  REQUIRE(w.host->exitStatus());
  CHECK(*w.host->exitStatus() == 4);
  CHECK(w.global("reached") == 0);
}

TEST_CASE("a message handler that never returns is interrupted with the call") {
  World w;
  lua_State* L = w.host->state();
  REQUIRE(luaL_dostring(L, R"(
    function handlerSpins() return xpcall(error, function() while true do end end, "x") end
    function bodyAndHandlerSpin()
      return xpcall(function() while true do end end, function(m) while true do end end)
    end
  )") == LUA_OK);
  for (const char* name : {"handlerSpins", "bodyAndHandlerSpin"}) {
    CAPTURE(name);
    lua_getglobal(L, name);
    CHECK_FALSE(w.host->call(0, 0, "test callback"));
    CHECK(w.logContains("still running after 100 ms: interrupted"));
  }
}

// require keeps the bytecode it compiled (sandbox.cpp, compiledModules): a new world, as a hot
// reload makes, loads a module it saw before without parsing it again. It must be the same
// module — its errors name the same file and line — and an edited file must be compiled afresh.
TEST_CASE("a module required again in a new world is the same module; an edited one is new") {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / ("pitwall_modules_" + std::to_string(getpid()));
  fs::create_directories(dir);
  auto save = [&](const char* text) { std::ofstream(dir / "cached_mod.lua") << text; };
  const std::string script = "package.path = '" + dir.string() +
                             "/?.lua;' .. package.path\n"
                             "local m = require 'cached_mod'\n"
                             "value = m.value\n"
                             "ok, err = pcall(m.fail)\n";
  auto run = [&](lua_Integer& value, std::string& err) {
    World w;
    REQUIRE(w.host->startString(script, "modules"));
    value = w.global("value");
    lua_getglobal(w.host->state(), "err");
    err = lua_tostring(w.host->state(), -1) ? lua_tostring(w.host->state(), -1) : "";
    lua_pop(w.host->state(), 1);
  };
  save("local M = {value = 1}\n\nfunction M.fail() error('line three') end\nreturn M\n");
  lua_Integer first = 0, second = 0, edited = 0;
  std::string firstErr, secondErr, editedErr;
  run(first, firstErr);
  run(second, secondErr);  // from the compiled cache
  CHECK(first == 1);
  CHECK(second == 1);
  CHECK(firstErr.find("cached_mod.lua:3: line three") != std::string::npos);
  CHECK(secondErr == firstErr);
  save("local M = {value = 2}\nfunction M.fail() error('line two') end\nreturn M\n");
  run(edited, editedErr);
  CHECK(edited == 2);
  CHECK(editedErr.find("cached_mod.lua:2: line two") != std::string::npos);
  fs::remove_all(dir);
}

// What the cache never holds: a device that never ends (/dev/zero) is loaded as Lua loads it,
// streamed, and fails at its first bad byte with an error, not with the process's memory.
TEST_CASE("require of an endless device fails with an error, within the script's memory") {
  World w(std::size_t{16} << 20);
  REQUIRE(
      w.host->startString("package.path = '/dev/?'\n"
                          "ok, err = pcall(require, 'zero')\n",
                          "endless"));
  lua_getglobal(w.host->state(), "err");
  std::string err = lua_tostring(w.host->state(), -1) ? lua_tostring(w.host->state(), -1) : "";
  lua_pop(w.host->state(), 1);
  CHECK(err.find("error loading module 'zero' from file '/dev/zero'") != std::string::npos);
}
