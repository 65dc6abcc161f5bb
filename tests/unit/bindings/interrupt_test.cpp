// Runaway Lua code is interrupted: callbacks over the budget, and anything at all on request
// (Ctrl-C at the REPL). The engine keeps running and the next call works.
#include "bindings/interrupt.hpp"

#include <doctest/doctest.h>
#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <thread>

#include "bindings/script_host.hpp"
#include "engine/core/log.hpp"

using namespace pitwall;
using namespace std::chrono_literals;

namespace {

std::atomic<bool> g_luaStarted{false};

int markStarted(lua_State*) {
  g_luaStarted = true;
  return 0;
}

struct RunawayFixture {
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  std::unique_ptr<ScriptHost> host;
  std::vector<std::string> logged;

  explicit RunawayFixture(std::chrono::milliseconds budget = 100ms) {
    setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
    HostOptions options;
    options.budget = budget;
    host = std::make_unique<ScriptHost>(loop, fleet, nullptr, options);
    lua_register(host->state(), "markStarted", markStarted);
    log::setSink([this](log::Level, std::string_view line) { logged.emplace_back(line); });
  }
  ~RunawayFixture() { log::setSink(nullptr); }

  // Calls the global function `name` as an event callback would be called.
  bool callback(const char* name) {
    lua_getglobal(host->state(), name);
    return host->call(0, 0, "test callback");
  }
  void define(const std::string& code) {
    REQUIRE(luaL_dostring(host->state(), code.c_str()) == LUA_OK);
  }
  std::string lastLog() const { return logged.empty() ? "" : logged.back(); }
};

}  // namespace

TEST_CASE("a callback that never returns is interrupted after the budget and reported") {
  RunawayFixture f;
  f.define("function spin() while true do end end  function fine() answer = 42 end");
  auto started = std::chrono::steady_clock::now();
  CHECK_FALSE(f.callback("spin"));
  auto took = std::chrono::steady_clock::now() - started;
  CHECK(took >= 100ms);
  CHECK(took < 2s);
  CHECK(f.lastLog().find("error in test callback") != std::string::npos);
  CHECK(f.lastLog().find("still running after 100 ms: interrupted") != std::string::npos);
  CHECK(f.lastLog().find("[string") != std::string::npos);  // where it was stopped
  // The engine and the Lua world carry on.
  CHECK(f.callback("fine"));
  lua_getglobal(f.host->state(), "answer");
  CHECK(lua_tointeger(f.host->state(), -1) == 42);
}

TEST_CASE("pcall cannot swallow the interruption") {
  RunawayFixture f;
  f.define(
      "caught = 0\n"
      "function stubborn()\n"
      "  while true do\n"
      "    local ok = pcall(function() while true do end end)\n"
      "    if not ok then caught = caught + 1 end\n"
      "  end\n"
      "end");
  CHECK_FALSE(f.callback("stubborn"));
  CHECK(f.lastLog().find("interrupted") != std::string::npos);
}

TEST_CASE("a runaway loop inside the script's own coroutine is interrupted too") {
  RunawayFixture f;
  f.define(
      "gen = coroutine.wrap(function() coroutine.yield(1) while true do end end)\n"
      "co = coroutine.create(function() while true do end end)\n"
      "function viaWrap() gen() gen() end\n"
      "function viaResume() local ok, err = coroutine.resume(co) error(err, 0) end\n"
      "function normal()\n"
      "  local g = coroutine.wrap(function(a) local b = coroutine.yield(a + 1) return b * 2 end)\n"
      "  assert(g(1) == 2 and g(5) == 10)\n"
      "  local c = coroutine.create(function() error('boom') end)\n"
      "  local ok, err = coroutine.resume(c)\n"
      "  assert(not ok and err:find('boom'))\n"
      "  local w = coroutine.wrap(function() error('bang') end)\n"
      "  local ok2, err2 = pcall(w)\n"
      "  assert(not ok2 and err2:find('bang'))\n"
      "  assert(select(2, coroutine.resume(c)) == 'cannot resume dead coroutine')\n"
      "end");
  CHECK_FALSE(f.callback("viaWrap"));
  CHECK(f.lastLog().find("still running after") != std::string::npos);
  CHECK_FALSE(f.callback("viaResume"));
  CHECK(f.lastLog().find("still running after") != std::string::npos);
  // The tracked resume and wrap keep Lua's own semantics.
  CHECK(f.callback("normal"));
}

TEST_CASE("a task that loops without sleeping is interrupted and ends") {
  RunawayFixture f;
  auto started = f.host->startString("while true do end", "busy.lua");
  REQUIRE(started);
  CHECK(f.host->mainFailed());
  bool found = false;
  for (const auto& l : f.logged)
    if (l.find("main chunk") != std::string::npos && l.find("busy.lua:1") != std::string::npos &&
        l.find("still running after") != std::string::npos)
      found = true;
  CHECK(found);
}

TEST_CASE("with the budget off a long callback runs to its end") {
  RunawayFixture f(0ms);
  f.define(
      "function long() local t = os.clock() while os.clock() - t < 0.3 do end done = true end");
  CHECK(f.callback("long"));
  lua_getglobal(f.host->state(), "done");
  CHECK(lua_toboolean(f.host->state(), -1));
}

TEST_CASE("a chunk typed at the REPL has no budget") {
  RunawayFixture f;
  REQUIRE(luaL_loadstring(f.host->state(),
                          "local t = os.clock() while os.clock() - t < 0.3 do end return 7") ==
          LUA_OK);
  std::string error;
  REQUIRE(f.host->callInteractive(0, 1, error));
  CHECK(lua_tointeger(f.host->state(), -1) == 7);
}

namespace {
// Stands for the loop's thread not running: preempted by a busy machine, waiting for a slow disk.
int stall(lua_State* L) {
  std::this_thread::sleep_for(std::chrono::milliseconds(luaL_checkinteger(L, 1)));
  return 0;
}
}  // namespace

TEST_CASE("time the loop's thread does not run is not charged to the callback") {
  // The budget is CPU time: a callback stalled for ten budgets by the machine is not
  // interrupted (on the wall clock it was, at its next instruction), and one that loops is.
  RunawayFixture f(20ms);
  lua_register(f.host->state(), "stall", stall);
  f.define(
      "function stalled() stall(200) local n = 0 for i = 1, 1000 do n = n + i end done = n end\n"
      "function spin() while true do end end");
  CHECK(f.callback("stalled"));
  lua_getglobal(f.host->state(), "done");
  CHECK(lua_tointeger(f.host->state(), -1) == 500500);
  lua_pop(f.host->state(), 1);
  CHECK_FALSE(f.callback("spin"));
  CHECK(f.lastLog().find("still running after 20 ms: interrupted") != std::string::npos);
}

TEST_CASE("many short callbacks under the budget are never interrupted") {
  RunawayFixture f(20ms);
  f.define("n = 0 function tick() for i = 1, 1000 do n = n + 1 end end");
  auto until = std::chrono::steady_clock::now() + 300ms;
  int calls = 0;
  while (std::chrono::steady_clock::now() < until) {
    REQUIRE(f.callback("tick"));
    ++calls;
  }
  CHECK(calls > 100);
}

namespace {
std::atomic<bool> g_requested{false};
void onTestSignal(int) {
  g_requested = pitwall::interrupt::requestFromSignal();
}
}  // namespace

TEST_CASE("an interrupt request stops a running REPL chunk and nothing else") {
  RunawayFixture f;
  struct sigaction sa {
  }, old{};
  sa.sa_handler = onTestSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGUSR1, &sa, &old);

  // Nothing runs: the request says so (the REPL then clears the line instead).
  g_requested = true;
  raise(SIGUSR1);
  CHECK_FALSE(g_requested);

  g_luaStarted = false;
  pthread_t self = pthread_self();
  std::thread ctrlC([self] {
    while (!g_luaStarted) std::this_thread::yield();
    pthread_kill(self, SIGUSR1);
  });
  REQUIRE(luaL_loadstring(f.host->state(), "markStarted() while true do end") == LUA_OK);
  std::string error;
  CHECK_FALSE(f.host->callInteractive(0, 0, error));
  ctrlC.join();
  CHECK(g_requested);
  CHECK(error.find("interrupted") != std::string::npos);
  CHECK(error.find("still running") == std::string::npos);
  sigaction(SIGUSR1, &old, nullptr);

  // The world still answers.
  REQUIRE(luaL_loadstring(f.host->state(), "return 1 + 1") == LUA_OK);
  REQUIRE(f.host->callInteractive(0, 1, error));
  CHECK(lua_tointeger(f.host->state(), -1) == 2);
}
