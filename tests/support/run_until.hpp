#pragma once
// Runs a loop until a condition holds, for tests and benchmarks that wait for something to
// happen over a real bus or socket (Loop::runUntil, with the tests' default limit of 5 s).
#include <functional>

#include "engine/core/loop.hpp"

namespace pitwall::testing {

inline bool runUntil(Loop& loop, const std::function<bool()>& done,
                     Duration limit = std::chrono::seconds(5)) {
  return loop.runUntil(done, limit);
}

// Runs the loop for `d` of loop time.
inline void runFor(Loop& loop, Duration d) {
  auto end = loop.now() + d;
  runUntil(
      loop, [&] { return loop.now() >= end; }, d + std::chrono::seconds(1));
}

}  // namespace pitwall::testing
