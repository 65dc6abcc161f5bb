#pragma once
// Runs a real-clock loop until a condition holds, for tests and benchmarks that wait for
// something to happen over a real bus or socket: the condition is checked every millisecond of
// loop time; the deadline bounds the wait. Leaves no timer behind.
#include <functional>

#include "engine/core/loop.hpp"

namespace pitwall::testing {

inline bool runUntil(Loop& loop, const std::function<bool()>& done,
                     Duration limit = std::chrono::seconds(5)) {
  if (done()) return true;
  bool met = false;  // done() may consume what it checks (a read): it is not called again
  Loop::TimerId poll = 0;
  std::function<void()> check = [&] {
    poll = 0;
    if (done()) {
      met = true;
      return loop.stop();
    }
    poll = loop.after(std::chrono::milliseconds(1), check);
  };
  poll = loop.after(std::chrono::milliseconds(1), check);
  auto deadline = loop.after(limit, [&] { loop.stop(); });
  loop.run();
  loop.cancel(deadline);
  if (poll) loop.cancel(poll);
  return met;
}

// Runs the loop for `d` of loop time.
inline void runFor(Loop& loop, Duration d) {
  auto end = loop.now() + d;
  runUntil(
      loop, [&] { return loop.now() >= end; }, d + std::chrono::seconds(1));
}

}  // namespace pitwall::testing
