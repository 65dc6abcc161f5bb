#pragma once
// This thread's CPU time, as a std::chrono clock: blocks timed with it do not count time the
// thread spent preempted (the benchmark machines are shared; see docs/performance.md).
#include <time.h>

#include <chrono>

namespace pitwall::bench {

struct ThreadCpuClock {
  using duration = std::chrono::nanoseconds;
  using time_point = std::chrono::time_point<ThreadCpuClock>;
  static time_point now() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return time_point(std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec));
  }
};

}  // namespace pitwall::bench
