#include "bindings/interrupt.hpp"

#include <pthread.h>
#include <signal.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <mutex>
#include <optional>
#include <thread>

#include "bindings/protected_call.hpp"

namespace pitwall::interrupt {

namespace detail {
std::atomic<lua_State*> g_running{nullptr};
std::atomic<int> g_depth{0};
std::atomic<int> g_kind{0};
std::atomic<std::uint64_t> g_call{0};
std::atomic<int> g_reason{kNoReason};
std::atomic<long long> g_budgetMs{0};
}  // namespace detail

namespace {

enum Reason : int { kNone = detail::kNoReason, kUser = 1, kBudget = 2, kMessage = 3 };

// All of this is written on the loop's thread; the watchdog only reads. The signal handler runs
// on the loop's thread too (the watchdog sends it there), so it sees the loop's own writes.
// Scope's own state (g_running, g_depth, g_kind, g_call, g_reason) is in interrupt.hpp's
// detail namespace, so that Scope is inline on the event hot path.
using detail::g_budgetMs;
using detail::g_call;
using detail::g_depth;
using detail::g_kind;
using detail::g_reason;
using detail::g_running;
std::atomic<std::uint64_t> g_target{0};      // the call the watchdog found over budget
std::atomic<std::uint64_t> g_reasonCall{0};  // … and which call that is
std::atomic<pthread_t> g_loopThread{};
std::atomic<clockid_t> g_loopClock{};  // the CPU-time clock of the loop's thread
std::atomic<bool> g_haveClock{false};
char g_message[256] = {};  // abortRunning's message; written on the loop's thread only
static_assert(std::atomic<lua_State*>::is_always_lock_free);
static_assert(std::atomic<std::uint64_t>::is_always_lock_free);
static_assert(std::atomic<pthread_t>::is_always_lock_free);
static_assert(std::atomic<clockid_t>::is_always_lock_free);

void hook(lua_State* L, lua_Debug*) {
  int reason = g_reason.load(std::memory_order_relaxed);
  if (reason == kNone ||
      g_reasonCall.load(std::memory_order_relaxed) != g_call.load(std::memory_order_relaxed)) {
    lua_sethook(L, nullptr, 0, 0);  // left over from a call that has ended: remove itself
    return;
  }
  // The hook stays set: code that catches this error with pcall is interrupted again at its
  // next instruction, until the engine's call returns.
  if (reason == kUser) luaL_error(L, "interrupted");
  if (reason == kMessage) luaL_error(L, "%s", g_message);
  // A task (the main chunk, a pitwall.spawn) runs in a coroutine; callbacks on the main thread.
  const bool task = lua_pushthread(L) == 0;
  lua_pop(L, 1);
  const int ms = static_cast<int>(g_budgetMs.load(std::memory_order_relaxed));
  const char* raise = detail::g_ownCall ? "--driver-budget" : "--budget";
  // Where it was running: the interrupted function (level 0 in a hook) when it is the script's,
  // else the script's nearest line, as the engine's errors blame (lua::pushUserWhere).
  lua_Debug ar;
  if (lua_getstack(L, 0, &ar) && lua_getinfo(L, "Sl", &ar) && ar.currentline > 0 &&
      !lua::isLibrarySource(L, ar.source))
    luaL_where(L, 0);
  else
    lua::pushUserWhere(L);
  if (task)
    lua_pushfstring(L,
                    "still running after %d ms without a pause: interrupted (a task must give the "
                    "loop its turn: call pitwall.sleep or pitwall.waitUntil in its loop, or raise "
                    "%s)",
                    ms, raise);
  else
    lua_pushfstring(L,
                    "still running after %d ms: interrupted (a callback must return quickly; run "
                    "long work in a task with pitwall.spawn and pitwall.sleep, or raise %s)",
                    ms, raise);
  lua_concat(L, 2);
  lua_error(L);
}

constexpr int kHookMask = LUA_MASKCALL | LUA_MASKRET | LUA_MASKLINE | LUA_MASKCOUNT;

// The call running now is being interrupted.
bool armedNow() {
  return g_reason.load(std::memory_order_relaxed) != kNone &&
         g_reasonCall.load(std::memory_order_relaxed) == g_call.load(std::memory_order_relaxed);
}

void arm(lua_State* L, int reason) {
  g_reasonCall.store(g_call.load(std::memory_order_relaxed), std::memory_order_relaxed);
  g_reason.store(reason, std::memory_order_relaxed);
  lua_sethook(L, hook, kHookMask, 1);  // lua_sethook may be called from a signal handler
}

void onBudgetSignal(int) {
  int saved = errno;
  lua_State* L = g_running.load(std::memory_order_relaxed);
  if (L && g_depth.load(std::memory_order_relaxed) > 0 &&
      g_kind.load(std::memory_order_relaxed) == static_cast<int>(Kind::Callback) &&
      g_target.load(std::memory_order_relaxed) == g_call.load(std::memory_order_relaxed) &&
      g_reason.load(std::memory_order_relaxed) == kNone)
    arm(L, kBudget);
  errno = saved;
}

// The CPU time the loop's thread has used; nullopt when it cannot be read (no thread watched, or
// the thread has ended).
std::optional<std::chrono::nanoseconds> loopCpuTime() {
  if (!g_haveClock.load(std::memory_order_relaxed)) return std::nullopt;
  timespec ts{};
  if (clock_gettime(g_loopClock.load(std::memory_order_relaxed), &ts) != 0) return std::nullopt;
  return std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec);
}

// Wakes a quarter of the running call's budget apart (its world's), at most kIdleNap; a call seen
// in progress twice, a budget of the loop thread's CPU time apart, is over budget. CPU time, not
// the wall clock: a callback is not to blame for a machine busy with other work, a slow disk or a
// stopped process (a race must not end because the host compiled something), while one that loops
// uses CPU time at the wall clock's pace.
constexpr std::chrono::milliseconds kIdleNap{20};

bool budgetedCallRunning() {
  return g_depth.load(std::memory_order_relaxed) > 0 &&
         g_kind.load(std::memory_order_relaxed) == static_cast<int>(Kind::Callback) &&
         g_budgetMs.load(std::memory_order_relaxed) > 0;
}

void watch() {
  std::uint64_t seen = 0;
  std::chrono::nanoseconds since{};
  bool sent = false;
  for (;;) {
    // Never longer than kIdleNap: the next call may belong to a world with a smaller budget.
    const long long before = budgetedCallRunning() ? g_budgetMs.load(std::memory_order_relaxed) : 0;
    std::this_thread::sleep_for(
        before > 0 ? std::min<std::chrono::milliseconds>(
                         kIdleNap, std::chrono::milliseconds(std::max(1LL, before / 4)))
                   : kIdleNap);
    const bool busy = budgetedCallRunning();
    const long long ms = g_budgetMs.load(std::memory_order_relaxed);
    std::uint64_t call = g_call.load(std::memory_order_relaxed);
    auto cpu = loopCpuTime();
    if (!busy || !cpu) {
      seen = 0;
      continue;
    }
    auto now = *cpu;
    if (call != seen) {
      seen = call;
      since = now;
      sent = false;
      continue;
    }
    if (!sent && now - since >= std::chrono::milliseconds(ms)) {
      g_target.store(call, std::memory_order_relaxed);
      sent = true;
      pthread_kill(g_loopThread.load(std::memory_order_relaxed), SIGURG);
    }
  }
}

void startWatchdog() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction sa {};
    sa.sa_handler = onBudgetSignal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGURG, &sa, nullptr);
    // The watchdog takes no signals: SIGINT and SIGURG must reach the loop's thread, where the
    // Lua code runs. It lives as long as the process and touches only the atomics.
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &old);
    std::thread(watch).detach();
    pthread_sigmask(SIG_SETMASK, &old, nullptr);
  });
}

// xpcall whose message handler is not run for an interrupt's error. Lua runs a message handler
// where the error was raised; for an error raised by the interrupt's hook that is inside the hook,
// where Lua turns hooks off, so a handler that loops could never be interrupted again. An
// interrupt's error reaches the xpcall as it is; every other error goes through the handler.
int guardedHandler(lua_State* L) {
  if (armedNow()) return 1;
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, 1);
  return 1;
}

int afterXpcall(lua_State* L, int status, lua_KContext) {
  if (status != LUA_OK && status != LUA_YIELD) {
    lua_pushboolean(L, 0);
    lua_pushvalue(L, -2);
    return 2;
  }
  return lua_gettop(L) - 2;  // `true` and the function's results
}

int guardedXpcall(lua_State* L) {
  const int n = lua_gettop(L);
  luaL_checktype(L, 2, LUA_TFUNCTION);
  lua_pushboolean(L, 1);  // the first result when the call succeeds
  lua_pushvalue(L, 1);    // the function
  lua_rotate(L, 3, 2);    // both below the arguments
  lua_pushvalue(L, 2);
  lua_pushcclosure(L, guardedHandler, 1);
  lua_replace(L, 2);  // the handler, guarded
  return afterXpcall(L, lua_pcallk(L, n - 2, LUA_MULTRET, 2, 0, afterXpcall), 0);
}

// Closes `co`'s pending to-be-closed variables. Their __close functions run on `co`: the
// interrupter is told so, or a __close that loops there could not be interrupted (the hook would go
// on the thread that called close).
int closeIn(lua_State* L, lua_State* co) {
  Running running(co);
#if LUA_VERSION_RELEASE_NUM >= 50406
  return lua_closethread(co, L);
#else
  (void)L;
  return lua_resetthread(co);
#endif
}

// coroutine.close(co), as Lua's (lcorolib.c, luaB_close), with closeIn.
int trackedClose(lua_State* L) {
  lua_State* co = lua_tothread(L, 1);
  luaL_argexpected(L, co, 1, "coroutine");
  lua_Debug ar;
  if (co == L) return luaL_error(L, "cannot close a running coroutine");
  if (lua_status(co) == LUA_OK && lua_getstack(co, 0, &ar))  // it resumed the one running
    return luaL_error(L, "cannot close a normal coroutine");
  if (closeIn(L, co) == LUA_OK) {
    lua_pushboolean(L, 1);
    return 1;
  }
  lua_pushboolean(L, 0);
  lua_xmove(co, L, 1);  // the error
  return 2;
}

// coroutine.resume and coroutine.wrap that say which thread runs.
int resumeIn(lua_State* L, lua_State* co, int nargs) {
  if (!lua_checkstack(co, nargs)) {
    lua_pushliteral(L, "too many arguments to resume");
    return -1;
  }
  lua_xmove(L, co, nargs);
  int nres = 0;
  int status;
  {
    Running running(co);
    status = lua_resume(co, L, nargs, &nres);
  }
  if (status == LUA_OK || status == LUA_YIELD) {
    if (!lua_checkstack(L, nres + 1)) {
      lua_pop(co, nres);
      lua_pushliteral(L, "too many results to resume");
      return -1;
    }
    lua_xmove(co, L, nres);
    return nres;
  }
  lua_xmove(co, L, 1);  // the error
  return -1;
}

int trackedResume(lua_State* L) {
  lua_State* co = lua_tothread(L, 1);
  luaL_argexpected(L, co, 1, "coroutine");
  int r = resumeIn(L, co, lua_gettop(L) - 1);
  lua_pushboolean(L, r >= 0);
  lua_insert(L, r >= 0 ? -(r + 1) : -2);
  return r >= 0 ? r + 1 : 2;
}

int wrapped(lua_State* L) {
  lua_State* co = lua_tothread(L, lua_upvalueindex(1));
  int r = resumeIn(L, co, lua_gettop(L));
  if (r >= 0) return r;
  int status = lua_status(co);
  if (status != LUA_OK && status != LUA_YIELD) {  // the coroutine died: close it, as 5.4 does
    closeIn(L, co);
    lua_xmove(co, L, 1);
  }
  if (lua_type(L, -1) == LUA_TSTRING) {  // where the wrapper was called, as 5.4 adds
    luaL_where(L, 1);
    lua_insert(L, -2);
    lua_concat(L, 2);
  }
  return lua_error(L);
}

int trackedWrap(lua_State* L) {
  luaL_checktype(L, 1, LUA_TFUNCTION);
  lua_State* co = lua_newthread(L);
  lua_pushvalue(L, 1);
  lua_xmove(L, co, 1);
  lua_pushcclosure(L, wrapped, 1);
  return 1;
}

}  // namespace

Running::Running(lua_State* co) : previous_(g_running.load(std::memory_order_relaxed)) {
  g_running.store(co, std::memory_order_relaxed);
  // Interrupted while switching threads: the new one is interrupted too.
  if (g_reason.load(std::memory_order_relaxed) != kNone &&
      g_reasonCall.load(std::memory_order_relaxed) == g_call.load(std::memory_order_relaxed))
    lua_sethook(co, hook, kHookMask, 1);
}

Running::~Running() {
  g_running.store(previous_, std::memory_order_relaxed);
  // Interrupted inside the coroutine: the thread that resumed it is interrupted too, so a pcall
  // around the resume cannot catch the interrupt and carry on.
  if (previous_ && armedNow()) lua_sethook(previous_, hook, kHookMask, 1);
}

void watchThisThread(bool budgeted) {
  g_loopThread.store(pthread_self(), std::memory_order_relaxed);
  clockid_t clock{};
  if (pthread_getcpuclockid(pthread_self(), &clock) == 0) {
    g_loopClock.store(clock, std::memory_order_relaxed);
    g_haveClock.store(true, std::memory_order_relaxed);
  }
  if (budgeted) startWatchdog();
}

bool requestFromSignal() {
  lua_State* L = g_running.load(std::memory_order_relaxed);
  if (!L || g_depth.load(std::memory_order_relaxed) == 0) return false;
  arm(L, kUser);
  return true;
}

void abortRunning(const std::string& message) {
  std::size_t n = std::min(message.size(), sizeof g_message - 1);
  message.copy(g_message, n);
  g_message[n] = '\0';
  lua_State* L = g_running.load(std::memory_order_relaxed);
  if (L && g_depth.load(std::memory_order_relaxed) > 0) arm(L, kMessage);
}

bool inCall() {
  return g_depth.load(std::memory_order_relaxed) > 0;
}

bool inConsole() {
  return g_depth.load(std::memory_order_relaxed) > 0 &&
         g_kind.load(std::memory_order_relaxed) == static_cast<int>(Kind::Console);
}

void openCoroutineTracking(lua_State* L) {
  lua_getglobal(L, "coroutine");
  if (!lua_istable(L, -1)) {
    lua_pop(L, 1);
    return;
  }
  lua_pushcfunction(L, trackedResume);
  lua_setfield(L, -2, "resume");
  lua_pushcfunction(L, trackedWrap);
  lua_setfield(L, -2, "wrap");
  lua_pushcfunction(L, trackedClose);
  lua_setfield(L, -2, "close");
  lua_pop(L, 1);
  lua_pushcfunction(L, guardedXpcall);
  lua_setglobal(L, "xpcall");
}

}  // namespace pitwall::interrupt
