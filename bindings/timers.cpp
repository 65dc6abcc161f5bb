#include "bindings/timers.hpp"

#include "bindings/script_host.hpp"

namespace pitwall {

Timers::Timers(ScriptHost& host) : host_(host), loop_(host.loop()) {}

Timers::~Timers() {
  for (auto& [handle, timer] : timers_) loop_.cancel(timer.id);
}

int Timers::add(lua_State* L, Duration first, std::optional<Duration> period) {
  int handle = next_++;
  if (host_.isShutDown()) {  // the run is ending: a timer that never fires
    lua_pop(L, 1);
    return handle;
  }
  Timer t;
  // Errors name the timer by where its function was written: two failing timers are two places
  // (the error flood counts each apart), not one "pitwall.every callback".
  std::string what = period ? "pitwall.every callback" : "pitwall.after callback";
  lua_pushvalue(L, -1);
  lua_Debug ar;
  if (lua_getinfo(L, ">S", &ar) && ar.linedefined > 0)
    what.append(" (").append(ar.short_src).append(":").append(std::to_string(ar.linedefined)) +=
        ')';
  t.what = std::make_shared<const std::string>(std::move(what));
  t.fnRef = luaL_ref(L, LUA_REGISTRYINDEX);
  t.period = period;
  t.due = loop_.now() + first;
  t.id = loop_.at(t.due, [this, handle] { fire(handle); });
  timers_.emplace(handle, t);
  return handle;
}

bool Timers::cancel(int handle) {
  auto it = timers_.find(handle);
  if (it == timers_.end()) return false;
  loop_.cancel(it->second.id);
  luaL_unref(host_.state(), LUA_REGISTRYINDEX, it->second.fnRef);
  timers_.erase(it);
  return true;
}

void Timers::shutDown() {
  for (auto& [handle, timer] : timers_) {
    loop_.cancel(timer.id);
    luaL_unref(host_.state(), LUA_REGISTRYINDEX, timer.fnRef);
  }
  timers_.clear();
}

void Timers::fire(int handle) {
  auto it = timers_.find(handle);
  if (it == timers_.end()) return;
  lua_State* L = host_.state();
  Timer& t = it->second;
  int fnRef = t.fnRef;
  bool repeating = t.period.has_value();
  if (repeating) {
    // Scheduled before the call, so the callback may cancel it; due times do not drift. A timer
    // that is behind (its callback is slower than its period, or the loop was busy) skips the
    // ticks it missed instead of queueing them: the next tick is the next one in phase after
    // now, so a hog slows itself, never the engine (docs/lua-api.md).
    auto skipMissed = [this](Timer& timer) {
      if (const TimePoint now = loop_.now(); timer.due <= now)
        timer.due += (((now - timer.due) / *timer.period) + 1) * *timer.period;
    };
    t.due += *t.period;
    skipMissed(t);
    const Loop::TimerId id = t.id = loop_.at(t.due, [this, handle] { fire(handle); });
    lua_rawgeti(L, LUA_REGISTRYINDEX, fnRef);
    auto what = t.what;  // (the callback may cancel the timer)
    host_.call(0, 0, what->c_str());
    // A callback slower than its period: its next tick is the first after it returned, so the
    // timers that came due while it ran go first.
    auto again = timers_.find(handle);
    if (again != timers_.end() && again->second.id == id && again->second.due <= loop_.now()) {
      loop_.cancel(id);
      skipMissed(again->second);
      again->second.id = loop_.at(again->second.due, [this, handle] { fire(handle); });
    }
  } else {
    auto what = std::move(t.what);
    timers_.erase(it);
    lua_rawgeti(L, LUA_REGISTRYINDEX, fnRef);
    luaL_unref(L, LUA_REGISTRYINDEX, fnRef);
    host_.call(0, 0, what->c_str());
  }
}

}  // namespace pitwall
