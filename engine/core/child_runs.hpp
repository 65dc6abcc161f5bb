#pragma once
// Programs run beside the loop, never on it (the code page's Test runs `pitwall try`, docs/
// classroom.md): each a child process with its output read asynchronously, at most `parallel` at
// once and the rest queued (bounded), each killed when it runs past its time or writes past its
// output's cap. The children run at a lower priority (nice 10) in a process group of their own:
// thirty students' tests share the machine with the live race without making its loop late, and
// a Ctrl-C in the terminal reaches the run, not them. Whatever is still running when the
// ChildRuns goes is killed. Real time only (the timeouts are the steady clock's).
#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/core/loop.hpp"

namespace pitwall {

struct ChildOutcome {
  int status = -1;       // the exit status; -1 when it did not exit by itself (killed, not started)
  std::string out, err;  // what it wrote (each cut at the cap)
  bool timedOut = false;  // killed: it ran past its time
  bool tooLong = false;   // killed: it wrote past the cap
  int signal = 0;         // the signal that ended it, if one did
  std::string failure;    // it could not be started: why
  double seconds = 0;     // from its start to its end (wall clock)
  double waited = 0;      // in the queue before it started
};

struct ChildLimits {
  int parallel = 1;                              // children at once
  std::size_t queue = 64;                        // waiting at most; more are refused
  std::chrono::milliseconds timeout{30000};      // a child's time
  std::size_t maxOutput = std::size_t{4} << 20;  // bytes of stdout and of stderr, each
  int nice = 10;                                 // added to the children's niceness
};

class ChildRuns {
 public:
  using Done = std::function<void(ChildOutcome)>;
  ChildRuns(Loop& loop, ChildLimits limits);
  ~ChildRuns();  // kills every child still running (their `done` is not called)
  ChildRuns(const ChildRuns&) = delete;
  ChildRuns& operator=(const ChildRuns&) = delete;

  // Runs argv[0] (a path) with its arguments, stdin from /dev/null; `done` on the loop when it
  // ended. False (and `done` never called) when the queue is full.
  bool run(std::vector<std::string> argv, Done done);
  std::size_t running() const { return running_; }
  std::size_t queued() const { return queue_.size(); }
  const ChildLimits& limits() const { return limits_; }

 private:
  struct Job;
  void startNext();
  void start(std::shared_ptr<Job> job);
  void finished(const std::shared_ptr<Job>& job);

  Loop& loop_;
  ChildLimits limits_;
  std::deque<std::shared_ptr<Job>> queue_;
  std::vector<std::weak_ptr<Job>> live_;
  std::size_t running_ = 0;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace pitwall
