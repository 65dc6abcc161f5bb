#include "engine/cli/repl_chunk.hpp"

#include <doctest/doctest.h>

#include <memory>
#include <string>

using namespace pitwall::cli;

namespace {

struct State {
  std::unique_ptr<lua_State, void (*)(lua_State*)> L{luaL_newstate(), lua_close};
  State() { luaL_openlibs(L.get()); }
  lua_State* get() { return L.get(); }
};

// Runs the chunk compiled on top of the stack; returns its results joined by ",".
std::string runResults(lua_State* L) {
  int base = lua_gettop(L) - 1;
  REQUIRE(lua_pcall(L, 0, LUA_MULTRET, 0) == LUA_OK);
  std::string out;
  for (int i = base + 1; i <= lua_gettop(L); ++i) {
    if (i > base + 1) out += ",";
    out += luaL_tolstring(L, i, nullptr);
    lua_pop(L, 1);
  }
  lua_settop(L, base);
  return out;
}

}  // namespace

TEST_CASE("an expression typed alone returns its value (the return trick)") {
  State s;
  Chunk chunk = compileChunk(s.get(), "1 + 2");
  REQUIRE(chunk.status == ChunkStatus::Ready);
  CHECK(runResults(s.get()) == "3");
}

TEST_CASE("a line starting with = is `return` and the rest") {
  State s;
  REQUIRE(compileChunk(s.get(), "=1 + 2, 'x'").status == ChunkStatus::Ready);
  CHECK(runResults(s.get()) == "3,x");
  REQUIRE(compileChunk(s.get(), "=").status == ChunkStatus::Ready);
  CHECK(runResults(s.get()) == "");
}

TEST_CASE("a call shows what it returned") {
  State s;
  REQUIRE(compileChunk(s.get(), "select(2, 'a', 'b')").status == ChunkStatus::Ready);
  CHECK(runResults(s.get()) == "b");
}

TEST_CASE("a statement runs as a statement and returns nothing") {
  State s;
  REQUIRE(compileChunk(s.get(), "x = 5").status == ChunkStatus::Ready);
  CHECK(runResults(s.get()) == "");
  REQUIRE(compileChunk(s.get(), "x").status == ChunkStatus::Ready);
  CHECK(runResults(s.get()) == "5");
  REQUIRE(compileChunk(s.get(), "return x * 2").status == ChunkStatus::Ready);
  CHECK(runResults(s.get()) == "10");
  REQUIRE(compileChunk(s.get(), "for i = 1, 3 do x = x + i end").status == ChunkStatus::Ready);
  CHECK(runResults(s.get()) == "");
}

TEST_CASE("a comment alone is an empty chunk, not an unfinished expression") {
  State s;
  REQUIRE(compileChunk(s.get(), "-- nothing here").status == ChunkStatus::Ready);
  CHECK(runResults(s.get()) == "");
}

TEST_CASE("a function definition asks for lines until its end") {
  State s;
  CHECK(compileChunk(s.get(), "function add(a, b)").status == ChunkStatus::Incomplete);
  CHECK(compileChunk(s.get(), "function add(a, b)\n  return a + b").status ==
        ChunkStatus::Incomplete);
  REQUIRE(compileChunk(s.get(), "function add(a, b)\n  return a + b\nend").status ==
          ChunkStatus::Ready);
  CHECK(runResults(s.get()) == "");
  REQUIRE(compileChunk(s.get(), "add(2, 40)").status == ChunkStatus::Ready);
  CHECK(runResults(s.get()) == "42");
}

TEST_CASE("an unfinished expression, call, table or long string asks for more") {
  State s;
  for (const char* text : {"1 +", "=1 +", "print(1,", "t = {1,", "=[[abc", "x = ("}) {
    CAPTURE(text);
    Chunk chunk = compileChunk(s.get(), text);
    CHECK(chunk.status == ChunkStatus::Incomplete);
    CHECK(chunk.error.find("<eof>") != std::string::npos);
  }
  REQUIRE(compileChunk(s.get(), "1 +\n2").status == ChunkStatus::Ready);
  CHECK(runResults(s.get()) == "3");
}

TEST_CASE("a syntax error no further line can fix is reported, named stdin") {
  State s;
  Chunk chunk = compileChunk(s.get(), "x = = 1");
  CHECK(chunk.status == ChunkStatus::Invalid);
  CHECK(chunk.error.rfind("stdin:1:", 0) == 0);
  CHECK(compileChunk(s.get(), "end").status == ChunkStatus::Invalid);
  CHECK(compileChunk(s.get(), "=1 +* 2").status == ChunkStatus::Invalid);
}

TEST_CASE("only a ready chunk leaves something on the stack") {
  State s;
  lua_State* L = s.get();
  int top = lua_gettop(L);
  compileChunk(L, "function f()");
  CHECK(lua_gettop(L) == top);
  compileChunk(L, "x = = 1");
  CHECK(lua_gettop(L) == top);
  compileChunk(L, "1 + 1");
  CHECK(lua_gettop(L) == top + 1);
  CHECK(lua_isfunction(L, -1));
}

TEST_CASE("errors and values of a multi-line chunk name its lines") {
  State s;
  REQUIRE(compileChunk(s.get(), "local a = 1\nerror('boom')").status == ChunkStatus::Ready);
  lua_State* L = s.get();
  REQUIRE(lua_pcall(L, 0, 0, 0) == LUA_ERRRUN);
  CHECK(std::string(lua_tostring(L, -1)) == "stdin:2: boom");
}
