#include "bindings/tasks.hpp"

#include "bindings/interrupt.hpp"
#include "bindings/lua_args.hpp"
#include "bindings/misspelled_method.hpp"
#include "bindings/script_host.hpp"

#include <algorithm>
#include <optional>

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
  Task task;
  task.name = main ? name : "task " + name;
  start(L, std::move(task), main);
}

lua_State* Tasks::spawnConsole(lua_State* L, Finished finished) {
  Task task;
  task.name = "the chunk typed at the prompt";
  task.kind = interrupt::Kind::Console;
  task.finished = std::move(finished);
  lua_State* co = start(L, std::move(task), false);
  // Ended at once: its thread was let go after `finished`, and nothing made since can have
  // its address while it was anchored.
  return co && tasks_.count(co) ? co : nullptr;
}

lua_State* Tasks::start(lua_State* L, Task task, bool main) {
  if (host_.isShutDown()) {
    lua_pop(L, 1);
    return nullptr;
  }
  lua_State* co = lua_newthread(L);
  task.threadRef = luaL_ref(L, LUA_REGISTRYINDEX);  // pops the thread, keeps it alive
  task.order = ++spawned_;
  lua_xmove(L, co, 1);  // the function
  tasks_.emplace(co, std::move(task));
  if (main) main_ = co;
  resume(co, 0);
  return co;
}

std::string Tasks::cancel(lua_State* co) {
  auto it = tasks_.find(co);
  if (it == tasks_.end()) return {};
  if (it->second.wake) loop_.cancel(*it->second.wake);
  lua_State* L = host_.state();
  // "stdin:1: interrupted while waiting": the typed line it waited at (not the library's)
  std::string message = "interrupted while waiting";
  lua_Debug ar;
  for (int level = 0; lua_getstack(co, level, &ar); ++level) {
    if (lua_getinfo(co, "Sl", &ar) && ar.currentline > 0 && !lua::isLibrarySource(co, ar.source)) {
      message = std::string(ar.short_src) + ":" + std::to_string(ar.currentline) + ": " + message;
      break;
    }
  }
  lua::pushTraceback(L, co, message.c_str(), 0);
  std::string where = lua_tostring(L, -1);
  lua_pop(L, 1);
  Task task = std::move(it->second);
  tasks_.erase(it);
  {
    // Closing runs the chunk's to-be-closed variables: Lua code, which Ctrl-C must reach too.
    std::optional<interrupt::Scope> scope;
    std::optional<interrupt::OwnScope> own;  // a driver world's: its budget its own
    if (host_.ownBudget())
      own.emplace(co, task.kind, host_.options().budget);
    else
      scope.emplace(co, task.kind, host_.options().budget);
    closeThread(co);
  }
  luaL_unref(L, LUA_REGISTRYINDEX, task.threadRef);
  return where;
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
      bool own = ar.currentline > 0 && !lua::isLibrarySource(co, ar.source);
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
    std::optional<interrupt::Scope> scope;
    std::optional<interrupt::OwnScope> own;  // a driver world's: its budget its own
    if (host_.ownBudget())
      own.emplace(co, tasks_.at(co).kind, host_.options().budget);
    else
      scope.emplace(co, tasks_.at(co).kind, host_.options().budget);
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
    if (!msg) {  // its __tostring runs on the host's thread: co died with the error
      lua_pushvalue(co, -1);
      lua_xmove(co, L, 1);
      lua::errorObjectText(L, -1, host_.options().budget);
      lua_xmove(L, co, 1);  // the text, kept alive on co
      lua_pop(L, 1);        // the error's copy
      msg = lua_tostring(co, -1);
    }
    std::optional<std::string> explained;
    explained = lua::explainMissingName(co, 0, msg);  // car:setSped → a suggestion
    if (explained) msg = explained->c_str();
    lua::pushTraceback(L, co, msg, 0);
    error = lua_tostring(L, -1);
    lua_pop(L, 1);
  }
  end(co, error, status == LUA_OK ? nres : 0);
}

void Tasks::end(lua_State* co, const std::string& error, int nresults) {
  auto it = tasks_.find(co);
  Task task = std::move(it->second);
  tasks_.erase(it);
  // The callback may run Lua and start tasks: the task is out of the map by then, its thread
  // still anchored (its results are read from its stack).
  if (task.finished) task.finished(co, nresults, error);
  closeThread(co);
  luaL_unref(host_.state(), LUA_REGISTRYINDEX, task.threadRef);
  const std::string& where = task.name;
  if (task.finished) return;
  if (co == main_) {
    main_ = nullptr;
    host_.mainEnded(where, error);
  } else if (!error.empty()) {
    host_.reportError(where, error);
  }
}

}  // namespace pitwall
