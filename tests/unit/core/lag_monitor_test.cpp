#include "engine/core/lag_monitor.hpp"

#include <doctest/doctest.h>

#include <thread>

using namespace pitwall;
using namespace std::chrono_literals;

// The adversary: a callback that holds the loop 45 ms of every 50 ms (a script's long handler,
// or a machine too busy). Within a few seconds the monitor says the loop fell behind — once —
// and once the hog is gone and the loop kept up for its window, that it caught up.
TEST_CASE("lag monitor: a loop held most of the time is behind, once; then it catches up") {
  Loop loop(ClockKind::Real);
  LagMonitor lag(loop);
  int behind = 0, caughtUp = 0;
  double mean = 0;
  bool hogging = true;
  lag.onBehind = [&](double ms) {
    ++behind;
    mean = ms;
    hogging = false;  // the hog ends: the loop keeps up again
  };
  lag.onCaughtUp = [&] {
    ++caughtUp;
    loop.stop();
  };
  std::function<void()> hog = [&] {
    if (!hogging) return;
    std::this_thread::sleep_for(45ms);
    loop.after(5ms, hog);
  };
  loop.after(10ms, hog);
  auto guard = loop.after(30s, [&] { loop.stop(); });
  loop.run();
  loop.cancel(guard);
  CHECK(behind == 1);
  CHECK(mean > 10);
  CHECK(caughtUp == 1);
  CHECK_FALSE(lag.behind());
}

// A loop whose timers all run on time (a virtual clock: never late, whatever the machine does)
// is never said to be behind, however long it runs. (On the real clock a loaded machine does
// make the loop late, and then the warning is right: no test may count on an idle machine.)
TEST_CASE("lag monitor: a loop that keeps up is never said to be behind") {
  Loop loop(ClockKind::Virtual);
  LagMonitor lag(loop);
  int behind = 0, ticks = 0;
  lag.onBehind = [&](double) { ++behind; };
  std::function<void()> work = [&] {
    if (++ticks < 20000) loop.after(5ms, work);
  };
  loop.after(5ms, work);
  loop.after(60s, [&] { loop.stop(); });
  loop.run();
  CHECK(ticks > 1000);
  CHECK(behind == 0);
}
