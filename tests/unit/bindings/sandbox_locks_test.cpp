// No back door in the sandbox (docs/safety.md, issue 33): every metatable a world's registry
// holds is locked (bindings/metatables.hpp), so no script reaches one to plant a finalizer, which
// Lua would run with hooks off (past the budget and Ctrl-C); and every other way to code that
// runs where the budget cannot reach is tried, each refused with a sentence or made harmless.
#include <doctest/doctest.h>

#include <cstring>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "bindings/metatables.hpp"
#include "bindings/script_host.hpp"
#include "engine/core/log.hpp"
#include "engine/sim/grid.hpp"
#include "engine/sim/track.hpp"
#include "engine/sim/world.hpp"
#include "tests/support/sim_cars.hpp"

using namespace pitwall;

namespace {

// A world with the simulator, so that every type a run can have is registered (the car, the
// seat, the script under test, the robots: each binding registers its metatable when it opens).
struct LockedWorld {
  Loop loop{ClockKind::Virtual};
  SimSession sim;
  Fleet fleet{loop};
  std::unique_ptr<ScriptHost> host;
  std::vector<std::string> logged;

  LockedWorld() {
    setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
    sim.world = std::make_unique<sim::World>(loop, *sim::loadLayout("oval"), 1);
    testing::addSimulatedCar(loop, fleet, *sim.world, sim::gridSpec(sim.world->track(), 0));
    auto until = loop.after(std::chrono::seconds(1), [&] { loop.stop(); });
    loop.run();
    loop.cancel(until);
    host = std::make_unique<ScriptHost>(loop, fleet, &sim, HostOptions{});
    log::setSink([this](log::Level, std::string_view line) { logged.emplace_back(line); });
  }
  ~LockedWorld() { log::setSink(nullptr); }

  // Runs `code` as the engine runs a callback (the budget and the memory cap apply); its error,
  // as the host reported it, or "" when it ran to the end.
  std::string run(const std::string& code) {
    lua_State* L = host->state();
    if (luaL_loadstring(L, code.c_str()) != LUA_OK) {
      std::string e = lua_tostring(L, -1);
      lua_pop(L, 1);
      return "does not compile: " + e;
    }
    logged.clear();
    if (host->call(0, 0, "attack")) return "";
    std::string all;
    for (const auto& line : logged) all += line + "\n";
    return all.empty() ? "(failed, nothing logged)" : all;
  }
};

// Registry entries that are tables but no metatable a value can have: Lua's own bookkeeping.
const std::set<std::string> kNotMetatables = {
    "_LOADED",   // package.loaded: scripts see it anyway
    "_PRELOAD",  // package.preload: likewise
    "_CLIBS",    // the C libraries loaded (scripts cannot reach the registry)
};

}  // namespace

TEST_CASE("every metatable in a world's registry is locked, and getmetatable gives its face") {
  LockedWorld w;
  lua_State* L = w.host->state();
  std::set<std::string> seen, unlocked;
  lua_pushnil(L);
  while (lua_next(L, LUA_REGISTRYINDEX)) {
    if (lua_type(L, -2) == LUA_TSTRING && lua_istable(L, -1)) {
      const std::string key = lua_tostring(L, -2);
      if (!kNotMetatables.count(key)) {
        seen.insert(key);
        if (!lua::isLocked(L, -1)) unlocked.insert(key);
      }
    }
    lua_pop(L, 1);
  }
  std::string names;
  for (const auto& n : unlocked) names += n + " ";
  // A new type whose metatable was not locked with lua::lockMetatable is named here.
  CHECK_MESSAGE(unlocked.empty(), "not locked: ", names);
  for (const char* expected : {"pitwall.timer", "pitwall.seat", "pitwall.car", "FILE*"})
    CHECK_MESSAGE(seen.count(expected), expected, " is not in the registry");

  // The strings' metatable is no registry entry: it is locked too.
  lua_pushliteral(L, "");
  REQUIRE(lua_getmetatable(L, -1));
  CHECK(lua::isLocked(L, -1));
  lua_pop(L, 2);

  // What the REPL and the editor's definitions read is on the face.
  CHECK(w.run(R"(
    local t = pitwall.after(10, function() end)
    for _, get in ipairs { getmetatable, debug.getmetatable } do
      local mt = get(t)
      assert(type(mt) == "table", "a face")
      assert(mt.__name == "timer", tostring(mt.__name))
      assert(type(mt.__methods.cancel) == "function", "the timer's methods")
      assert(getmetatable(mt) == "locked", "the face's own metatable is hidden")
    end
    assert(getmetatable("").__index == string, "the strings' methods are the string library")
    string.shout = function(s) return s:upper() .. "!" end
    assert(("go"):shout() == "GO!", "scripts may still extend the string library")
    t:cancel()
  )") == "");
}

TEST_CASE("issue 33's attack: a finalizer on the timers' metatable is refused with a sentence") {
  LockedWorld w;
  // Today's behaviour before the lock: the __gc was planted, and ran with hooks off forever.
  const std::string error = w.run(R"(
    local t = pitwall.after(10, function() end)
    local mt = getmetatable(t)
    mt.__gc = function() while true do end end
  )");
  CHECK(
      error.find("cannot set __gc on the metatable of timer: the engine's metatables are locked") !=
      std::string::npos);
  // and the timers still work, and collecting them runs nothing of the script's
  CHECK(w.run(R"(
    collectgarbage() collectgarbage()
    local fired = false
    pitwall.after(0, function() fired = true end)
  )") == "");
}

// pitwall._setHub trusted any value's __objecttype: a table given one that is a timer made the
// engine read a timer's box as a type (the review of issue 37's rework). Only an engine object's
// type counts now; the rest is refused with the sentence for a wrong value.
TEST_CASE("a table dressed as an engine object is refused, not read as one") {
  for (const char* fake : {"{__objecttype = pitwall.after(1e9, print)}", "{__objecttype = 42}",
                           "{__objecttype = {}}"}) {
    LockedWorld w;  // (a world each: the log tells one place's repeated error as a count)
    const std::string error =
        w.run(std::string("pitwall._setHub(setmetatable({}, ") + fake + "), 'onPing', print)");
    CAPTURE(std::string(fake));
    CAPTURE(error);
    CHECK(error.find("expected a car or a robot (an object with events), got table") !=
          std::string::npos);
  }
  // a real car still takes its hub
  CHECK(LockedWorld().run("pitwall._setHub(pitwall.cars()[1], 'onPing', print)") == "");
}

TEST_CASE("a type's own __index, given another value, refuses it with a sentence") {
  // A script never reaches it (getmetatable gives a face without it); the engine's own code
  // could: __index checks its object against its metatable (an upvalue, lua_object.cpp), so a
  // timer, a table, a string or nothing given to a car's field reader is refused, not read.
  LockedWorld w;
  lua_State* L = w.host->state();
  REQUIRE(luaL_getmetatable(L, "pitwall.car") == LUA_TTABLE);
  REQUIRE(lua_getfield(L, -1, "__index") == LUA_TFUNCTION);
  lua_setglobal(L, "READ");  // (a test's back door, to call it from Lua)
  lua_pop(L, 1);
  CHECK(w.run(R"(
    for _, other in ipairs { pitwall.after(1e9, print), {}, "speed", 42, io.stdout } do
      local ok, err = pcall(READ, other, "speed")
      assert(not ok, type(other) .. " was read as a car")
      assert(err:find("expected a car", 1, true), err)
    end
    assert(not pcall(READ), "nothing was read as a car")
    assert(READ(pitwall.cars()[1], "number") == 1, "a car's own field")
  )") == "");
}

// Each back door a script could try, and the sentence that refuses it ("" for none: the chunk
// itself errors when the attempt had an effect it must not have).
TEST_CASE("the sandbox's back doors, tried one by one, are each refused or harmless") {
  struct Attack {
    const char* name;
    const char* code;
    const char* refusal;
  };
  const Attack attacks[] = {
      {"debug.getmetatable on a timer", R"(
        debug.getmetatable(pitwall.after(1, print)).__gc = function() end)",
       "cannot set __gc on the metatable of timer"},
      {"a metamethod other than __gc", R"(
        getmetatable(pitwall.after(1, print)).__close = function() end)",
       "cannot set __close on the metatable of timer"},
      {"__mode on an engine metatable", R"(
        getmetatable(pitwall.after(1, print)).__mode = "k")",
       "cannot set __mode on the metatable of timer"},
      {"replacing a locked metatable's own metatable", R"(
        setmetatable(getmetatable(pitwall.after(1, print)), {}))",
       "cannot change a protected metatable"},
      {"the strings' metatable", R"(
        getmetatable("").__gc = function() while true do end end)",
       "cannot set __gc on the metatable of string"},
      {"a file handle's metatable", R"(
        getmetatable(io.stdout).__gc = function() while true do end end)",
       "cannot set __gc on the metatable of FILE*"},
      {"a file handle's metatable through debug", R"(
        debug.getmetatable(io.stderr).__index.close = function() end
        io.stderr:write(""))",
       ""},
      {"a car's metatable", R"(
        getmetatable(pitwall.cars()[1]).__gc = function() end)",
       "cannot set __gc on the metatable of car"},
      {"rawset on the face changes nothing of the engine's", R"(
        local ran = false
        rawset(getmetatable(pitwall.after(1, print)), "__gc", function() ran = true end)
        for i = 1, 10 do pitwall.after(1, print):cancel() end
        collectgarbage() collectgarbage()
        assert(not ran, "a finalizer ran"))",
       ""},
      {"setmetatable with a __gc", R"(
        setmetatable({}, { __gc = function() while true do end end }))",
       "a __gc finalizer is refused"},
      {"a __gc added after setmetatable is never called (Lua 5.4 marks an object for "
       "finalization only when setmetatable sees __gc)",
       R"(
        local ran = false
        local mt = {}
        local t = setmetatable({}, mt)
        mt.__gc = function() ran = true end
        t = nil
        collectgarbage() collectgarbage()
        assert(not ran, "a finalizer added after setmetatable ran"))",
       ""},
      {"a class that gains __gc after its first object: the next setmetatable refuses it",
       R"(
        local Class = {}
        Class.__index = Class
        local first = setmetatable({}, Class)
        Class.__gc = function() while true do end end
        local second = setmetatable({}, Class))",
       "a __gc finalizer is refused"},
      {"an object's own table (its uservalue) takes no finalizer", R"(
        local uv = debug.getuservalue(pitwall.after(1, print), 1)
        if type(uv) == "table" then setmetatable(uv, { __gc = print }) end
        error("a __gc finalizer is refused - no uservalue table to try"))",
       "a __gc finalizer is refused"},
      {"debug.setmetatable is not there", R"(
        debug.setmetatable(pitwall.after(1, print), { __gc = print }))",
       "setmetatable"},
      {"debug.getregistry is not there", R"(
        debug.getregistry()["pitwall.timer"].__gc = print)",
       "getregistry"},
      {"a __close that loops, run by coroutine.close", R"(
        local co = coroutine.create(function()
          local x <close> = setmetatable({}, { __close = function() while true do end end })
          coroutine.yield()
        end)
        coroutine.resume(co)
        coroutine.close(co))",
       "still running after"},
      {"a __close that loops, run when a wrapped coroutine fails", R"(
        local f = coroutine.wrap(function()
          local x <close> = setmetatable({}, { __close = function() while true do end end })
          error("boom")
        end)
        f())",
       "still running after"},
      {"a __close that loops, run when the budget interrupts", R"(
        local x <close> = setmetatable({}, { __close = function() while true do end end })
        while true do end)",
       "still running after"},
      {"an error object whose __tostring loops", R"(
        error(setmetatable({}, { __tostring = function() while true do end end })))",
       "still running after"},
      {"a message handler that loops", R"(
        xpcall(error, function() while true do end end, "x"))",
       "still running after"},
  };
  for (const Attack& a : attacks) {
    CAPTURE(a.name);
    LockedWorld w;
    const std::string error = w.run(a.code);
    if (*a.refusal == '\0') {
      CHECK_MESSAGE(error == "", error);
    } else {
      CHECK_MESSAGE(error.find(a.refusal) != std::string::npos, error);
    }
  }
}

// Many attempts at once: every metamethod name, on every engine value a script can hold, through
// both getters, with plain and raw writes. A write to a new field must be refused with the
// sentence; whatever went into a face (raw writes, fields it has) must change nothing the engine
// does: no planted function ever runs, objects made afterwards still work, collecting runs none.
TEST_CASE("every metamethod on every engine value, by every way in, is refused or inert") {
  LockedWorld w;
  CHECK(w.run(R"(
    local events = { "__gc", "__close", "__mode", "__index", "__newindex", "__call", "__tostring",
      "__len", "__eq", "__lt", "__le", "__concat", "__unm", "__add", "__name", "__metatable",
      "__pairs", "__methods", "__fields", "__events", "__idiv", "__band", "__shl", "__bnot" }
    local ran = 0
    local planted = function() ran = ran + 1 while true do end end
    local values = {
      timer = function() return pitwall.after(10, print) end,
      car = function() return pitwall.cars()[1] end,
      string = function() return "" end,
      file = function() return io.stdout end,
    }
    local tried, refused = 0, 0
    for name, make in pairs(values) do
      for _, get in ipairs { getmetatable, debug.getmetatable } do
        for _, key in ipairs(events) do
          local face = get(make())
          assert(type(face) == "table", name .. ": no face")
          local had = rawget(face, key) ~= nil
          local ok, err = pcall(function() face[key] = planted end)
          tried = tried + 1
          if not had then
            assert(not ok, name .. "." .. key .. " was set")
            assert(err:find("the engine's metatables are locked", 1, true), err)
            refused = refused + 1
          end
          rawset(face, key, planted)  -- changes the copy alone
          assert(not pcall(setmetatable, face, {}), name .. ": the face's metatable changed")
        end
      end
    end
    assert(tried == 4 * 2 * #events, tried)
    assert(refused >= 4 * (#events - 5), refused)  -- a face has at most 5 fields of its own
    -- the engine's values behave as before
    for i = 1, 20 do pitwall.after(1, print):cancel() end
    assert(tostring(pitwall.after(1, print)):find("^timer"), "a timer's __tostring")
    assert(tostring(pitwall.cars()[1]):find("^car 1"), "a car's __tostring")
    assert(("abc"):upper() == "ABC", "string methods")
    assert(#"abc" == 3 and "a" .. "b" == "ab", "string operators")
    io.stdout:write("")
    collectgarbage() collectgarbage()
    assert(ran == 0, "a planted function ran " .. ran .. " times")
  )") == "");
}
