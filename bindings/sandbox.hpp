#pragma once
// What a script may touch, and how much memory its Lua world may take (docs/safety.md).
//
// Redis's function_lua.c is the model: the engine decides what the world holds, and a script
// cannot reach past it to crash or wedge the engine.
// - Code is loaded as text only: load, loadfile, dofile and require refuse precompiled chunks
//   (Lua does not verify bytecode: patched bytecode crashes the process).
// - The debug library keeps only what reads and reaches nothing of the engine (traceback,
//   getinfo, getmetatable, getuservalue, upvalueid): debug.sethook would disarm the callback
//   budget, debug.debug reads the terminal, the setters and the registry reach into the engine's
//   references, getupvalue/getlocal into its C functions. load is written anew, not wrapped.
// - No __gc finalizers (setmetatable refuses them): Lua runs them with hooks off, where nothing
//   interrupts them, and again when the world closes. The metatables of strings and files are
//   locked as the engine's own are (bindings/metatables.hpp), and debug.getmetatable is
//   getmetatable: no script reaches a metatable that already marks objects for finalization.
// - Nothing may block the loop: io.read, io.input, io.stdin, io.lines() on stdin, io.popen and
//   os.execute are gone; so is package.loadlib (any function of any library). Files (io.open)
//   stay: scripts write results.
// - os.exit ends the run through the engine's stop path (ScriptHost), with its exit status.
// - Each world's allocations are counted against a cap (default 512 MB): a script that reaches it
//   gets the error "script memory limit of N MB reached", which pcall cannot swallow, and the run
//   ends through the stop path.
#include <lua.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace pitwall::sandbox {

// A world's cap unless it chooses its own (HostOptions::memory_limit, --lua-memory MB).
inline constexpr std::size_t kDefaultMemoryLimit = std::size_t{512} << 20;

// The memory of one Lua world. `limit` 0: no cap.
struct Memory {
  std::size_t used = 0;
  std::size_t limit = kDefaultMemoryLimit;
  // What the engine keeps for this world outside Lua and charges to its cap (the copy of the race
  // table pitwall.view.race gave the view, bindings/copy_budget.hpp).
  std::size_t outside = 0;
  bool exceeded = false;  // the cap was reached (Lua's emergency collection did not help)
  // The last request refused: Lua retries a refused allocation once after a full collection, and
  // only that retry failing too means the script really holds that much.
  const void* refusedPtr = nullptr;
  std::size_t refusedOld = 0, refusedNew = 0;
  int refusals = 0;
  bool driver = false;  // a driver world's: its cap is --driver-memory (docs/drivers.md)
};

// "script memory limit of 512 MB reached (…what to do…)"
std::string memoryMessage(const Memory& memory);

// A new Lua state whose allocations are counted in `memory` (which must outlive it), against
// its `limit` (0: no cap), which the world chose.
lua_State* newState(Memory& memory);

// After luaL_openlibs: the restrictions above (os.exit is the host's, see ScriptHost).
void restrict(lua_State* L);
// After restrict, for a driver world (docs/drivers.md): no file is read or written (io's files,
// loadfile, dofile, os.remove, … refused with a sentence; os.getenv too), and require finds only
// what `path` (Lua's "DIR/?.lua;…" form) finds — fixed now: changing package.path moves nothing.
void restrictToLibrary(lua_State* L, const std::string& path);

// Compiles each Lua file into this process's module cache, as require would (a file that does
// not compile is left out: require reports it). A process that forks a child per race (pitwall
// league) does this once before, so no child parses the library again.
void compileAhead(const std::vector<std::string>& files);

}  // namespace pitwall::sandbox
