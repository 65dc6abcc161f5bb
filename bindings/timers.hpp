#pragma once
// The timers of one Lua world (pitwall.after, pitwall.every) on the engine clock. A repeating
// timer that falls behind skips the ticks it missed instead of queueing them (docs/lua-api.md).
#include <lua.hpp>

#include <memory>
#include <optional>
#include <string>
#include <unordered_map>

#include "engine/core/loop.hpp"

namespace pitwall {

class ScriptHost;

class Timers {
 public:
  explicit Timers(ScriptHost& host);
  ~Timers();  // cancels them on the loop; their functions go with the Lua state
  Timers(const Timers&) = delete;
  Timers& operator=(const Timers&) = delete;

  // A timer of the function on top of L's stack (popped): first due after `first`, then every
  // `period` if given. Returns its handle; once the run is ending, a timer that never fires.
  int add(lua_State* L, Duration first, std::optional<Duration> period);
  // false when `handle` names no live timer (fired once, cancelled, or never made)
  bool cancel(int handle);
  // The run is ending: every timer is cancelled and its function released.
  void shutDown();

 private:
  struct Timer {
    int fnRef = LUA_NOREF;
    Loop::TimerId id = 0;
    std::optional<Duration> period;
    TimePoint due{};
    // "pitwall.every callback (race.lua:12)", as errors name it (shared: a tick copies it)
    std::shared_ptr<const std::string> what;
  };
  void fire(int handle);

  ScriptHost& host_;
  Loop& loop_;  // the host's
  std::unordered_map<int, Timer> timers_;
  int next_ = 1;
};

}  // namespace pitwall
