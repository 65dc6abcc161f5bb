#pragma once
// The tasks of one Lua world (pitwall.spawn, pitwall.sleep, the script's main chunk): coroutines
// resumed on the engine loop. A task that fails is reported with its traceback through the
// host; how the main chunk ended is the host's to judge (ScriptHost::mainEnded).
#include <lua.hpp>

#include <functional>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "bindings/interrupt.hpp"
#include "engine/core/loop.hpp"

namespace pitwall {

class ScriptHost;

class Tasks {
 public:
  explicit Tasks(ScriptHost& host);
  ~Tasks();  // cancels the wake-ups; the threads go with the Lua state
  Tasks(const Tasks&) = delete;
  Tasks& operator=(const Tasks&) = delete;

  // A task: a coroutine of the function on top of L's stack (L: the calling thread, which may
  // itself be a task), run at once until it sleeps or ends. `main`: the script's main chunk,
  // named `name` as it is; others are "task NAME".
  void spawn(lua_State* L, const std::string& name, bool main = false);
  // How a chunk typed at the REPL ended: its `nresults` results on top of `co`'s stack (read
  // them before returning: the coroutine is closed after), or `error` with its traceback.
  using Finished = std::function<void(lua_State* co, int nresults, const std::string& error)>;
  // A chunk typed at the REPL (the function on top of L's stack) as a task, so that it may
  // pitwall.sleep: Ctrl-C interrupts it and the callback budget does not apply
  // (interrupt::Kind::Console) whenever it runs; how it ends goes to `finished`, not to the
  // log. Returns its coroutine while it waits, nullptr when it ended at once (`finished` has
  // been called then).
  lua_State* spawnConsole(lua_State* L, Finished finished);
  // Ends a task that waits (Ctrl-C on a chunk asleep at the prompt): its wake-up is cancelled
  // and its coroutine closed, nothing is reported. Returns "stdin:1: interrupted while
  // waiting" (the innermost line of Lua it waited at) and the traceback.
  std::string cancel(lua_State* co);
  // Called by pitwall.sleep from inside a task: resume it after `delay`.
  void sleep(lua_State* co, Duration delay);
  // The run is ending: no task wakes again (each stays asleep for good).
  void shutDown();
  // One line per task alive, oldest first: "main chunk waiting at stuck_test.lua:4 (in sleep)"
  // — for a scenario stuck until its timeout.
  std::vector<std::string> waiting() const;

 private:
  struct Task {
    int threadRef = LUA_NOREF;
    std::string name;  // as errors name it: "main chunk", "task lap.lua:12"
    std::optional<Loop::TimerId> wake;
    std::uint64_t order = 0;  // spawned as the order-th task
    interrupt::Kind kind = interrupt::Kind::Callback;
    Finished finished;  // a chunk typed at the REPL: told how it ended
  };
  lua_State* start(lua_State* L, Task task, bool main);  // the coroutine; nullptr: not started
  void resume(lua_State* co, int nargs);
  // error empty: it returned, with `nresults` results on its stack
  void end(lua_State* co, const std::string& error, int nresults = 0);

  ScriptHost& host_;
  Loop& loop_;  // the host's
  std::unordered_map<lua_State*, Task> tasks_;
  lua_State* main_ = nullptr;
  std::uint64_t spawned_ = 0;
};

}  // namespace pitwall
