// Each Lua world has its own limits (issue 37): a memory cap, a callback budget and the way its
// tracebacks treat the library belong to the world, not to the process, so two worlds side by
// side — a race and a driver's world, a reload's two versions — may differ.
#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "bindings/script_host.hpp"
#include "engine/core/log.hpp"
#include "tests/support/temp_dir.hpp"

using namespace pitwall;
using namespace std::chrono_literals;

namespace {

struct World {
  Fleet fleet;
  std::unique_ptr<ScriptHost> host;

  World(Loop& loop, std::size_t memoryLimit, std::chrono::milliseconds budget, bool libraryFrames)
      : fleet(loop) {
    setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
    HostOptions options;
    options.memory_limit = memoryLimit;
    options.budget = budget;
    options.library_frames = libraryFrames;
    host = std::make_unique<ScriptHost>(loop, fleet, nullptr, options);
  }

  // Defines the global function `name` from `code` and calls it as an event callback is called.
  bool callback(const std::string& code, const char* name) {
    lua_State* L = host->state();
    REQUIRE(luaL_dostring(L, code.c_str()) == LUA_OK);
    lua_getglobal(L, name);
    return host->call(0, 0, "test callback");
  }
  bool global(const char* name) {
    lua_getglobal(host->state(), name);
    bool set = lua_toboolean(host->state(), -1);
    lua_pop(host->state(), 1);
    return set;
  }
};

// A table of 2^21 integers (32 MiB; 48 MiB while it grows): past a 16 MiB cap, under a 64 MiB
// one. (A table grows through Lua's allocator with its emergency collection, which is what tells
// the cap a script really holds that much.)
// 32 MB in four strings: past the small world's 16 MB cap at its second or third, in a few
// operations (a table of 2^21 numbers took longer than the small world's 20 ms budget under ASan
// on a busy machine, and the budget, not the cap, ended it: clean-clone run 43)
constexpr const char* kKeep32 = R"(
  function keep()
    kept = {}
    for i = 1, 4 do kept[i] = string.rep("x", (8 << 20) - 1) .. i end
    done = true
  end
)";

// 150 ms of CPU time, then it returns: past a 20 ms budget, under a 2 s one.
constexpr const char* kSpin150 = R"(
  function spin()
    local start = os.clock()
    while os.clock() - start < 0.15 do end
    spun = true
  end
)";

}  // namespace

TEST_CASE("two worlds side by side keep their own memory caps, budgets and traceback styles") {
  Loop loop{ClockKind::Virtual};
  std::vector<std::string> logged;
  log::setSink([&](log::Level, std::string_view line) { logged.emplace_back(line); });
  struct Unsink {  // also when a REQUIRE ends the case: the sink refers to `logged`
    ~Unsink() { log::setSink(nullptr); }
  } unsink;
  World small(loop, std::size_t{16} << 20, 20ms, false);
  World large(loop, std::size_t{64} << 20, 2000ms, true);

  SUBCASE("the memory cap") {
    CHECK(large.callback(kKeep32, "keep"));
    CHECK(large.global("done"));
    CHECK_FALSE(large.host->exitStatus());

    CHECK_FALSE(small.callback(kKeep32, "keep"));
    CHECK_FALSE(small.global("done"));
    REQUIRE(small.host->exitStatus());
    CHECK(*small.host->exitStatus() == 1);
    CHECK(small.host->memory().limit == (std::size_t{16} << 20));
    CHECK(large.host->memory().limit == (std::size_t{64} << 20));

    // the larger world is untouched by its neighbour's end, and still serves
    CHECK(large.callback("function again() done = false; collectgarbage() end", "again"));
    CHECK_FALSE(large.host->exitStatus());
  }

  SUBCASE("the callback budget") {
    CHECK_FALSE(small.callback(kSpin150, "spin"));
    CHECK_FALSE(small.global("spun"));
    bool said = false;
    for (const auto& line : logged)
      said = said || line.find("still running after 20 ms: interrupted") != std::string::npos;
    CHECK(said);

    CHECK(large.callback(kSpin150, "spin"));
    CHECK(large.global("spun"));

    // and again: the larger budget of the call before does not delay the smaller one's
    CHECK_FALSE(small.callback("function spin2() spin() end", "spin2"));
  }

  SUBCASE("the library's frames in tracebacks") {
    CHECK_FALSE(lua::framesOf(small.host->state()).libraryFrames);
    CHECK(lua::framesOf(large.host->state()).libraryFrames);
    // an error raised under the library (pitwall.copy, scripts/pitwall/core.lua): only the world
    // that lists the library's frames shows them
    const char* code =
        "function fail() pitwall.copy(setmetatable({}, {__pairs = function() error('boom') end})) "
        "end";
    std::string seen[2];
    World* worlds[2] = {&small, &large};
    for (int i = 0; i < 2; ++i) {
      logged.clear();
      CHECK_FALSE(worlds[i]->callback(code, "fail"));
      for (const auto& line : logged) seen[i] += line;
    }
    CHECK(seen[0].find("stack traceback:") != std::string::npos);
    CHECK(seen[1].find("stack traceback:") != std::string::npos);
    CHECK(seen[0].find("pitwall/core.lua") == std::string::npos);
    CHECK(seen[1].find("pitwall/core.lua") != std::string::npos);
  }
}

// pitwall.log from the world's own library names what it is about ("race: …"), never an
// installed file's line; from the script, its file and line. The library is the world's (here
// the source tree's, PITWALL_SCRIPTS), not the data folder's.
TEST_CASE("pitwall.log tells the world's library from the script") {
  Loop loop{ClockKind::Virtual};
  std::vector<std::string> logged;
  log::setSink([&](log::Level, std::string_view line) { logged.emplace_back(line); });
  struct Unsink {
    ~Unsink() { log::setSink(nullptr); }
  } unsink;
  World world(loop, sandbox::kDefaultMemoryLimit, interrupt::kDefaultBudget, true);
  lua_State* L = world.host->state();
  const std::string library = lua::framesOf(L).libraryChunks;  // "@…/scripts/pitwall/"
  REQUIRE(library.find(PITWALL_SOURCE_DIR "/scripts/pitwall/") != std::string::npos);
  const std::string code = "assert(load('pitwall.log(\"warn\", \"race: from the library\")', '" +
                           library + "fake.lua'))()\npitwall.log('warn', 'from the script')";
  REQUIRE(luaL_loadbuffer(L, code.data(), code.size(), "@user.lua") == LUA_OK);
  REQUIRE(world.host->call(0, 0, "test"));
  REQUIRE(logged.size() == 2);
  CHECK(logged[0].find("race: from the library") != std::string::npos);
  CHECK(logged[0].find("fake.lua") == std::string::npos);
  CHECK(logged[1].find("user.lua:2: from the script") != std::string::npos);
}

// The engine's own library loads under a budget of its own (ScriptHost::kLibraryBudget), not the
// callbacks': on a slow machine it took more than a callback's 100 ms (a QEMU guest under load,
// clean-clone run 57: "cannot load the pitwall Lua library … still running after 100 ms"). Here a
// library that takes 150 ms of CPU time to load opens a world whose callbacks get 100 ms, and
// those callbacks still get their 100 ms; one that never ends its loading still fails.
TEST_CASE("the library loads under its own budget; the world's callbacks keep theirs") {
  Loop loop(ClockKind::Virtual);
  Fleet fleet(loop);
  pitwall::testing::TempDir lib("pitwall-slow-lib");
  std::filesystem::create_directories(lib.path / "pitwall");
  HostOptions options;
  options.budget = 100ms;
  auto open = [&](const std::string& core) -> std::string {
    std::ofstream(lib.path / "pitwall" / "core.lua") << core;
    setenv("PITWALL_SCRIPTS", lib.path.c_str(), 1);
    std::string error;
    try {
      ScriptHost host(loop, fleet, nullptr, options);
      lua_State* L = host.state();
      REQUIRE(luaL_dostring(L, kSpin150) == LUA_OK);
      lua_getglobal(L, "spin");
      CHECK_FALSE(host.call(0, 0, "test callback"));  // the callbacks' budget is 100 ms still
    } catch (const std::exception& e) {
      error = e.what();
    }
    setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
    return error;
  };
  CHECK(open("local t = os.clock() while os.clock() - t < 0.15 do end return true\n") == "");
  const std::string never = open("while true do end\n");
  CHECK(never.find("cannot load the pitwall Lua library") != std::string::npos);
  CHECK(never.find("still running after 5000 ms") != std::string::npos);
}
