#include "bindings/tasks.hpp"

#include "bindings/interrupt.hpp"
#include "bindings/lua_args.hpp"
#include "bindings/misspelled_method.hpp"
#include "bindings/script_host.hpp"

#include <algorithm>

namespace pitwall {

namespace {
void closeThread(lua_State* co) {
#if LUA_VERSION_RELEASE_NUM >= 50406
  lua_closethread(co, nullptr);
#else
  lua_resetthread(co);
#endif
}
}  // namespace

Tasks::Tasks(ScriptHost& host) : host_(host), loop_(host.loop()) {}

Tasks::~Tasks() {
  for (auto& [co, task] : tasks_)
    if (task.wake) loop_.cancel(*task.wake);
}

void Tasks::spawn(lua_State* L, const std::string& name, bool main) {
  if (host_.isShutDown()) {
    lua_pop(L, 1);
    return;
  }
  lua_State* co = lua_newthread(L);
  int ref = luaL_ref(L, LUA_REGISTRYINDEX);  // pops the thread, keeps it alive
  lua_xmove(L, co, 1);                       // the function
  tasks_.emplace(co, Task{ref, main ? name : "task " + name, std::nullopt, ++spawned_});
  if (main) main_ = co;
  resume(co, 0);
}

void Tasks::sleep(lua_State* co, Duration delay) {
  auto it = tasks_.find(co);
  if (it == tasks_.end() || host_.isShutDown()) return;
  it->second.wake = loop_.after(delay, [this, co] {
    auto t = tasks_.find(co);
    if (t == tasks_.end()) return;
    t->second.wake.reset();
    resume(co, 0);
  });
}

std::vector<std::string> Tasks::waiting() const {
  std::vector<std::pair<std::uint64_t, std::string>> found;
  for (const auto& [co, task] : tasks_) {
    // The innermost of the script's own frames, and what it called (pitwall.sleep,
    // sim.runUntil, …): the library's frames and C functions are where, not why, it waits.
    std::string line = task.name + " waiting";
    std::string called;
    lua_Debug ar;
    for (int level = 0; lua_getstack(co, level, &ar); ++level) {
      if (!lua_getinfo(co, "Sln", &ar)) continue;
      bool own = ar.currentline > 0 && !lua::isLibrarySource(ar.source);
      if (!own) {
        if (ar.name) called = ar.name;
        continue;
      }
      line += " at " + std::string(ar.short_src) + ":" + std::to_string(ar.currentline);
      if (!called.empty()) line += " (in " + called + ")";
      break;
    }
    found.emplace_back(task.order, std::move(line));
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> lines;
  for (auto& f : found) lines.push_back(std::move(f.second));
  return lines;
}

void Tasks::shutDown() {
  for (auto& [co, task] : tasks_)
    if (task.wake) {
      loop_.cancel(*task.wake);
      task.wake.reset();
    }
}

void Tasks::resume(lua_State* co, int nargs) {
  if (host_.isShutDown() || !tasks_.count(co)) return;
  lua_State* L = host_.state();
  int nres = 0;
  int status;
  {
    interrupt::Scope scope(co, interrupt::Kind::Callback);
    status = lua_resume(co, L, nargs, &nres);
  }
  std::string error;
  if (status == LUA_YIELD) {
    lua_pop(co, nres);
    if (tasks_.at(co).wake) return;  // asleep: its timer resumes it
    if (host_.isShutDown()) return;  // the run ended while it ran: it stays asleep for good
    // A bare coroutine.yield() has nobody to wake it: end the task with a clear error.
    error =
        "the task yielded without pitwall.sleep or pitwall.waitUntil; nothing would ever "
        "resume it";
  } else if (status != LUA_OK && host_.memory().exceeded) {
    host_.checkMemory();
    error = sandbox::memoryMessage(host_.memory());
  } else if (status != LUA_OK) {
    const char* msg = lua::errorText(co, -1);
    std::optional<std::string> explained;
    if (msg) explained = lua::explainMissingMethod(co, 0, msg);  // car:setSped → a suggestion
    if (explained) msg = explained->c_str();
    lua::pushTraceback(L, co, msg ? msg : "(error without a message)", 0);
    error = lua_tostring(L, -1);
    lua_pop(L, 1);
  }
  end(co, error);
}

void Tasks::end(lua_State* co, const std::string& error) {
  auto it = tasks_.find(co);
  std::string where = it->second.name;
  closeThread(co);
  luaL_unref(host_.state(), LUA_REGISTRYINDEX, it->second.threadRef);
  tasks_.erase(it);
  if (co == main_) {
    main_ = nullptr;
    host_.mainEnded(where, error);
  } else if (!error.empty()) {
    host_.reportError(where, error);
  }
}

}  // namespace pitwall
