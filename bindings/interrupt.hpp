#pragma once
// Stopping Lua code that does not return: a runaway callback (the time budget, default 100 ms)
// and a chunk typed at the REPL (Ctrl-C). Both work the way lua.c's Ctrl-C does: a hook is set
// on the running Lua thread from a signal handler on the loop's own thread, and the hook raises
// an error at the next instruction. The hook stays set until the engine's call returns, so code
// cannot pcall its way out (Redis's rule). Nothing is paid on the hot path but two relaxed
// atomic stores per call into Lua: no count hook runs while nothing is wrong.
//
// The budget is watched by one thread that reads which call is in progress and the CPU time the
// loop's thread has used (its pthread CPU clock): a call that used a budget of CPU time is over
// budget; time the thread spent preempted, stopped or blocked does not count. The watchdog then
// signals the loop's thread (SIGURG), whose handler sets the hook.
#include <lua.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>

namespace pitwall::interrupt {

enum class Kind {
  Callback,  // a call from the engine (event, timer, task): subject to the budget
  Console,   // a chunk typed at the REPL: no budget, Ctrl-C interrupts it
};

namespace detail {
// What Scope keeps, written only on the loop's thread (by Scope, and by the signal handlers that
// run there: arming sets g_reason); the watchdog thread only reads it (interrupt.cpp). Here so that
// Scope is inline: it is on the path of every event.
extern std::atomic<lua_State*> g_running;  // the Lua thread running now, if any
extern std::atomic<int> g_depth;           // scopes on the stack
extern std::atomic<int> g_kind;            // Kind of the outermost scope
extern std::atomic<std::uint64_t> g_call;  // the number of the call now counted (g_calls)
extern std::atomic<int> g_reason;          // why the current call is being interrupted
extern std::atomic<long long> g_budgetMs;  // the outermost call's budget (its world's); 0: none
// Numbers every call, never the same twice (a call that resumes after an inner world's own call
// is a new one to the watchdog): written on the loop's thread only.
inline std::uint64_t g_calls = 0;
// The call counted now is a driver world's (OwnScope): the budget's message names
// --driver-budget. Written on the loop's thread only.
inline bool g_ownCall = false;
inline constexpr int kNoReason = 0;
}  // namespace detail

// Around every call from the engine into Lua (ScriptHost does this), with the budget of the world
// called (its own: worlds side by side may differ; zero: none). Only the outermost scope on the
// stack counts, with its budget; nested ones (a handler that triggers an event) are free.
class Scope {
 public:
  Scope(lua_State* running, Kind kind, std::chrono::milliseconds budget)
      : outermost_(detail::g_depth.load(std::memory_order_relaxed) == 0),
        previous_(detail::g_running.load(std::memory_order_relaxed)) {
    using namespace detail;
    if (outermost_) {
      g_call.store(++g_calls, std::memory_order_relaxed);
      g_kind.store(static_cast<int>(kind), std::memory_order_relaxed);
      g_budgetMs.store(budget.count() > 0 ? budget.count() : 0, std::memory_order_relaxed);
    }
    g_running.store(running, std::memory_order_relaxed);
    std::atomic_signal_fence(std::memory_order_seq_cst);
    g_depth.store(g_depth.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }
  ~Scope() {
    using namespace detail;
    g_depth.store(g_depth.load(std::memory_order_relaxed) - 1, std::memory_order_relaxed);
    std::atomic_signal_fence(std::memory_order_seq_cst);
    g_running.store(previous_, std::memory_order_relaxed);
    if (outermost_)
      g_reason.store(kNoReason, std::memory_order_relaxed);  // hooks remove themselves
  }
  Scope(const Scope&) = delete;
  Scope& operator=(const Scope&) = delete;

 private:
  bool outermost_;
  lua_State* previous_;
};

// A call into a world with a budget of its own (a driver world, docs/drivers.md), even inside
// another world's call (the race director's): a call of its own, with its budget, counted from
// its start. When it returns, the call around it goes on as a fresh call (its budget counts again
// from there: what the inner world used is not charged to it, and an interrupt the outer call had
// not yet taken is dropped, to be asked again). Its runaway's message names --driver-budget.
// Kept apart from Scope, which is on every event's path and pays nothing for it.
class OwnScope {
 public:
  OwnScope(lua_State* running, Kind kind, std::chrono::milliseconds budget)
      : outerKind_(detail::g_kind.load(std::memory_order_relaxed)),
        outerBudgetMs_(detail::g_budgetMs.load(std::memory_order_relaxed)),
        outerOwn_(detail::g_ownCall),
        nested_(detail::g_depth.load(std::memory_order_relaxed) > 0) {
    using namespace detail;
    g_reason.store(kNoReason, std::memory_order_relaxed);
    g_ownCall = true;
    g_call.store(++g_calls, std::memory_order_relaxed);
    g_kind.store(static_cast<int>(kind), std::memory_order_relaxed);
    g_budgetMs.store(budget.count() > 0 ? budget.count() : 0, std::memory_order_relaxed);
    previous_ = g_running.load(std::memory_order_relaxed);
    g_running.store(running, std::memory_order_relaxed);
    std::atomic_signal_fence(std::memory_order_seq_cst);
    g_depth.store(g_depth.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }
  ~OwnScope() {
    using namespace detail;
    g_depth.store(g_depth.load(std::memory_order_relaxed) - 1, std::memory_order_relaxed);
    std::atomic_signal_fence(std::memory_order_seq_cst);
    g_running.store(previous_, std::memory_order_relaxed);
    g_reason.store(kNoReason, std::memory_order_relaxed);  // hooks remove themselves
    g_ownCall = outerOwn_;
    if (nested_) {  // the outer call goes on as a fresh one
      g_kind.store(outerKind_, std::memory_order_relaxed);
      g_budgetMs.store(outerBudgetMs_, std::memory_order_relaxed);
      g_call.store(++g_calls, std::memory_order_relaxed);
    }
  }
  OwnScope(const OwnScope&) = delete;
  OwnScope& operator=(const OwnScope&) = delete;

 private:
  int outerKind_;
  long long outerBudgetMs_;
  bool outerOwn_;
  bool nested_;
  lua_State* previous_ = nullptr;
};

// The Lua thread now running changes (a task's coroutine resumed inside a scope, or a coroutine
// the script resumes itself): the hook must go on the thread that runs.
class Running {
 public:
  explicit Running(lua_State* co);
  ~Running();
  Running(const Running&) = delete;
  Running& operator=(const Running&) = delete;

 private:
  lua_State* previous_;
};

// A world's budget for its Kind::Callback calls, in CPU time of the loop's thread, unless it
// chooses its own (HostOptions::budget, --budget); zero turns it off.
inline constexpr std::chrono::milliseconds kDefaultBudget{100};
// The calling thread runs the Lua code (ScriptHost's constructor says so): the watchdog signals
// it. With `budgeted` (the world has a budget), starts the watchdog (once, for the process).
void watchThisThread(bool budgeted);

// For a SIGINT handler (async-signal-safe): interrupts the Lua code running now with the error
// "interrupted". Returns false when no Lua code is running (the caller then cancels the line).
bool requestFromSignal();

// Ends the Lua code running now with `message` (copied), the way the budget does: pcall cannot
// swallow it, until the engine's call returns. For the memory cap (sandbox.cpp).
void abortRunning(const std::string& message);

// True while the engine is inside a call into Lua (any kind).
bool inCall();

// True while a chunk typed at the REPL runs (the outermost call into Lua is Kind::Console):
// commands that need the operator's confirmation ask for it then.
bool inConsole();

// Replaces coroutine.resume and coroutine.wrap in L with versions that tell the interrupter
// which thread runs (so a runaway loop inside a script's own coroutine is caught too), and
// xpcall with one whose message handler never runs for an interrupt's error (Lua would run it
// with hooks off, where a loop in it could not be interrupted).
void openCoroutineTracking(lua_State* L);

}  // namespace pitwall::interrupt
