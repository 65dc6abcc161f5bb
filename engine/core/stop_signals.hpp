#pragma once
// SIGINT, SIGTERM and SIGHUP for a run (docs/safety.md). The handler does only async-signal-safe
// work: it counts the signal, calls an async-signal-safe hook (the bindings interrupt the Lua code
// running now, so a busy callback cannot hold Ctrl-C up), and wakes the loop through a pipe; the
// loop then calls onSignal. A virtual loop, which never sleeps, reads the pipe when the handler's
// count says there is something in it (Loop::setPassCheck) instead of keeping a read pending. A
// third signal that the loop has not acted on ends the process at once (_exit 130): the last word
// when the loop itself is wedged.
//
// Two more signals reach the loop the same way without counting towards that: SIGPIPE when
// stdout's or stderr's reader went away (`pitwall run … | head`; the output that is gone is
// pointed at /dev/null first, so the rest of the run's output is dropped, and the Lua code
// running is interrupted), and SIGTSTP (Ctrl-Z), which the loop answers by stopping the cars and
// then suspending the process itself (docs/safety.md).
#include <boost/asio/posix/stream_descriptor.hpp>
#include <csignal>
#include <functional>

#include "engine/core/loop.hpp"

namespace pitwall {

class StopSignals {
 public:
  using AsyncHook = void (*)();
  explicit StopSignals(Loop& loop);
  ~StopSignals();  // the previous handlers come back
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // On the loop: `count` is how many SIGINT/SIGTERM/SIGHUP arrived so far (1 for the first); 0
  // for SIGPIPE (an output's reader went away; once a run) and SIGTSTP (Ctrl-Z: suspend).
  std::function<void(int sig, int count)> onSignal;
  // Called inside the handler, on every signal; must be async-signal-safe.
  static void setAsyncHook(AsyncHook hook);
  // SIGINT is someone else's from now on (the REPL's own handler); SIGTERM stays.
  void releaseSigint();

 private:
  void await();
  void drain();  // a virtual loop's pass: the signals the handler counted since the last one
  void deliver(int sig);
  Loop& loop_;
  boost::asio::posix::stream_descriptor pipe_;
  int writeFd_ = -1;
  struct sigaction oldInt_ {
  }, oldTerm_{}, oldHup_{}, oldPipe_{}, oldTstp_{};
  bool hupCaught_ = false;   // not when SIGHUP was ignored (nohup)
  bool tstpCaught_ = false;  // not when SIGTSTP was ignored (no job control)
  bool sigintReleased_ = false;
  char byte_ = 0;
  int drained_ = 0;  // signals a virtual loop has read
};

}  // namespace pitwall
