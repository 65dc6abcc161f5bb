#pragma once
// The tasks of one Lua world (pitwall.spawn, pitwall.sleep, the script's main chunk): coroutines
// resumed on the engine loop. A task that fails is reported with its traceback through the
// host; how the main chunk ended is the host's to judge (ScriptHost::mainEnded).
#include <lua.hpp>

#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

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
  };
  void resume(lua_State* co, int nargs);
  void end(lua_State* co, const std::string& error);  // error empty: it returned

  ScriptHost& host_;
  Loop& loop_;  // the host's
  std::unordered_map<lua_State*, Task> tasks_;
  lua_State* main_ = nullptr;
  std::uint64_t spawned_ = 0;
};

}  // namespace pitwall
