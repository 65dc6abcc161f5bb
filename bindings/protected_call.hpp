#pragma once
// The one way the engine calls into Lua (Neovim's nlua_pcall is the model): lua::protectedCall
// runs a function under its world's budget and the interrupt (interrupt::Scope) with the message
// handler given. Every
// call from the engine — an event, a timer, the REPL's chunk, a hook, the library's prelude —
// goes through ScriptHost's call paths, which build on this one; no other file calls lua_pcall
// (tests/structure/bindings_test.py). Tasks are resumed (lua_resume, bindings/tasks.cpp) under
// the same Scope; the script's own pcall and xpcall are Lua calling Lua.
//
// Stack checks (Defold's DM_LUA_STACK_CHECK is the model): lua::StackCheck notes the top when it
// is made and, when it goes, compares it with what the code promised; a difference is reported
// (stackUnbalanced) naming the place, the top expected and the top found. PITWALL_STACK_CHECK
// places one where the engine promises a balanced stack around its calls (an event's delivery,
// lua::emit; ScriptHost's own calls); it is compiled in when PITWALL_STACK_CHECKS is 1: debug
// builds, the ASan build of the unit tests (`./dev test`), not release builds, where the event
// hot path stays as measured (docs/performance.md). lua_pcall itself keeps its promise; what can
// break one is the engine's code around it (a value pushed and never popped).
#include <lua.hpp>

#include <chrono>
#include <string>

#include "bindings/interrupt.hpp"

#ifndef PITWALL_STACK_CHECKS
#ifdef NDEBUG
#define PITWALL_STACK_CHECKS 0
#else
#define PITWALL_STACK_CHECKS 1
#endif
#endif

namespace pitwall::lua {

// The error's blame: what a failed call says, and which line it names.

// Pushes "file:line: " of the script's code that called into pitwall: the nearest Lua function
// on the stack that is not part of the shipped library (scripts/pitwall/), so that an error
// raised for a bad argument names the user's line even when it was passed through library
// functions (race.laps → drivers → car:setSpeed). "" when no such function is on the stack.
void pushUserWhere(lua_State* L);

// The message handler of every protected call: the error text plus a traceback.
int traceback(lua_State* L);

// The error message at idx as C text for the handlers: a string (or number) with NUL bytes in it
// is replaced at idx by one with each NUL written \x00, so no part of it is cut off; nullptr
// when it is no string.
const char* errorText(lua_State* L, int idx);
// An error that is no string, as text pushed onto L: what its __tostring says (called
// protected, under `budget` when no call into Lua is under way), else "(error object is a TYPE
// value)".
const char* errorObjectText(lua_State* L, int idx, std::chrono::milliseconds budget);

// How a world's tracebacks and blame tell the shipped library's frames from the user's: the
// library's chunk names ("@/usr/share/pitwall/scripts/pitwall/") and whether tracebacks list its
// frames (not in pitwall test without --verbose). Each world's own (its host keeps it, setFrames),
// found from any of its threads; a state with none set gets these defaults.
struct Frames {
  std::string libraryChunks = "@scripts/pitwall/";
  bool libraryFrames = true;
};
void setFrames(lua_State* L, const Frames* frames);  // `frames` outlives L (nullptr: defaults)
const Frames& framesOf(lua_State* L);

// Pushes `msg` and a traceback of L1 from `level` onto L, as luaL_traceback does; while L's
// world has libraryFrames off only the script's own frames are listed: the library's
// (scripts/pitwall/) and C functions' are left out.
void pushTraceback(lua_State* L, lua_State* L1, const char* msg, int level);
// True for a chunk of L's world's shipped library (scripts/pitwall/…): frames the user did not
// write.
bool isLibrarySource(lua_State* L, const char* source);

// What happens on an unbalanced stack: by default the message goes to stderr and the process
// aborts (a debug build's bug, found where it happens); a test installs its own to see it.
using StackFailure = void (*)(const char* where, int expected, int found);
StackFailure setStackFailure(StackFailure failure);  // returns the one before
void stackUnbalanced(const char* where, int expected, int found);

// The stack's top, when this goes, is to be `delta` above what it was when this was made.
class StackCheck {
 public:
  StackCheck(lua_State* L, int delta, const char* where)
      : L_(L), expected_(lua_gettop(L) + delta), where_(where) {}
  ~StackCheck() {
    if (const int found = lua_gettop(L_); found != expected_)
      stackUnbalanced(where_, expected_, found);
  }
  StackCheck(const StackCheck&) = delete;
  StackCheck& operator=(const StackCheck&) = delete;

 private:
  lua_State* L_;
  int expected_;
  const char* where_;
};

#if PITWALL_STACK_CHECKS
#define PITWALL_STACK_CONCAT2(a, b) a##b
#define PITWALL_STACK_CONCAT(a, b) PITWALL_STACK_CONCAT2(a, b)
// In debug builds: the stack's top, at the end of the enclosing block, is `delta` above its top
// here. In release builds: nothing.
#define PITWALL_STACK_CHECK(L, delta, where) \
  ::pitwall::lua::StackCheck PITWALL_STACK_CONCAT(stackCheck_, __LINE__)((L), (delta), (where))
#else
#define PITWALL_STACK_CHECK(L, delta, where) ((void)0)
#endif

// Calls the function under the top `nargs` values, as lua_pcall(L, nargs, nresults, handler)
// does, inside an interrupt::Scope of `kind` with the world's `budget`. Returns lua_pcall's
// status; on success the results are left (nresults of them), on failure the error.
inline int protectedCall(lua_State* L, int nargs, int nresults, int handler, interrupt::Kind kind,
                         std::chrono::milliseconds budget) {
  interrupt::Scope scope(L, kind, budget);
  return lua_pcall(L, nargs, nresults, handler);
}
// The same in a world whose budget is its own (a driver world's, interrupt::OwnScope); its
// callers are out of line, off the event hot path of the run's world.
inline int protectedOwnCall(lua_State* L, int nargs, int nresults, int handler,
                            interrupt::Kind kind, std::chrono::milliseconds budget) {
  interrupt::OwnScope scope(L, kind, budget);
  return lua_pcall(L, nargs, nresults, handler);
}

}  // namespace pitwall::lua
