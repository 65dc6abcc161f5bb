// Stack-balance checks (bindings/protected_call.hpp): a place that promises to leave the Lua stack
// as it found it, and does not, is reported with the place, the top expected and the top found.
// The engine's own check sites are compiled in debug builds (the ASan build of the unit tests that
// `./dev test` runs); this file asks for them in every build, so the event delivery's check below
// (lua::emit, a template made here for this file's own fill) runs in the release build too.
#define PITWALL_STACK_CHECKS 1
#include "bindings/protected_call.hpp"

#include <doctest/doctest.h>

#include <memory>
#include <string>
#include <vector>

#include "bindings/lua_object.hpp"
#include "bindings/script_host.hpp"
#include "engine/core/log.hpp"

using namespace pitwall;

namespace {

struct Unbalanced {
  std::string where;
  int expected, found;
};
std::vector<Unbalanced> g_seen;

void record(const char* where, int expected, int found) {
  g_seen.push_back({where, expected, found});
}

// Installs `record` for the case, and puts the default back however the case ends.
struct Recording {
  lua::StackFailure before;
  Recording() : before(lua::setStackFailure(record)) { g_seen.clear(); }
  ~Recording() { lua::setStackFailure(before); }
};

}  // namespace

TEST_CASE("a StackCheck reports a place that leaves one value too many or too few") {
  Recording recording;
  lua_State* L = luaL_newstate();
  lua_pushinteger(L, 1);
  {
    lua::StackCheck balanced(L, 0, "balanced");
    lua_pushinteger(L, 2);
    lua_pop(L, 1);
  }
  CHECK(g_seen.empty());
  {
    lua::StackCheck leaks(L, 0, "a leak");
    lua_pushinteger(L, 2);  // never popped
  }
  {
    lua::StackCheck pops(L, 1, "one result promised");
    lua_pop(L, 1);
  }
  REQUIRE(g_seen.size() == 2);
  CHECK(g_seen[0].where == "a leak");
  CHECK(g_seen[0].expected == 1);
  CHECK(g_seen[0].found == 2);
  CHECK(g_seen[1].where == "one result promised");
  CHECK(g_seen[1].expected == 3);
  CHECK(g_seen[1].found == 1);
  lua_close(L);
}

TEST_CASE("protectedCall leaves the results, or the error, and nothing else") {
  lua_State* L = luaL_newstate();
  luaL_openlibs(L);
  REQUIRE(luaL_loadstring(L, "return 1, 2, ...") == LUA_OK);
  lua_pushinteger(L, 3);
  CHECK(lua::protectedCall(L, 1, 3, 0, interrupt::Kind::Callback, {}) == LUA_OK);
  CHECK(lua_gettop(L) == 3);
  lua_settop(L, 0);
  REQUIRE(luaL_loadstring(L, "error('no')") == LUA_OK);
  CHECK(lua::protectedCall(L, 0, 2, 0, interrupt::Kind::Callback, {}) == LUA_ERRRUN);
  CHECK(lua_gettop(L) == 1);
  lua_close(L);
}

// A binding whose event fill leaves a value behind (a lua_getfield it forgot to pop): the call
// goes wrong, and the debug check names the delivery.
TEST_CASE("an event whose fill leaves a value on the stack trips the debug check") {
  Recording recording;
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
  std::vector<std::string> logged;
  log::setSink([&](log::Level, std::string_view line) { logged.emplace_back(line); });
  struct Unsink {
    ~Unsink() { log::setSink(nullptr); }
  } unsink;
  ScriptHost host(loop, fleet, nullptr, HostOptions{});
  lua_State* L = host.state();
  static const char* const kNames[] = {"onThing"};
  lua::EventNames names(kNames);
  lua::EventSlots slots;
  REQUIRE(luaL_dostring(L, "return function(self, t) seen = t.value end") == LUA_OK);
  slots.setHandler(L, 0, -1);
  lua_pop(L, 1);
  lua_newtable(L);
  const int self = luaL_ref(L, LUA_REGISTRYINDEX);
  const lua::EventSource source{host, slots, names, self, "thing 1"};
  const int top = lua_gettop(L);

  lua::emit(source, 0, LUA_NOREF, [](lua_State* L) { lua::setInteger(L, "value", 7); });
  CHECK(g_seen.empty());
  CHECK(lua_gettop(L) == top);

  lua::emit(source, 0, LUA_NOREF, [](lua_State* L) {
    lua::setInteger(L, "value", 8);
    lua_getglobal(L, "seen");  // and never popped
  });
  REQUIRE(g_seen.size() == 1);
  CHECK(g_seen[0].where == std::string("an event's delivery (lua::emit)"));
  CHECK(g_seen[0].found == g_seen[0].expected + 1);
  lua_settop(L, top);
  slots.release(L);
  luaL_unref(L, LUA_REGISTRYINDEX, self);
}
