#include "engine/core/loop.hpp"

#include <doctest/doctest.h>

#include <functional>
#include <vector>

using namespace pitwall;
using namespace std::chrono_literals;

TEST_CASE("a virtual loop jumps straight to the next due timer") {
  Loop loop(ClockKind::Virtual);
  std::vector<double> fired;
  loop.after(10s, [&] { fired.push_back(loop.seconds()); });
  loop.after(2s, [&] { fired.push_back(loop.seconds()); });
  loop.run();
  CHECK(fired == std::vector<double>{2.0, 10.0});
  CHECK(loop.seconds() == 10.0);
}

TEST_CASE("timers due at the same instant fire in the order they were scheduled") {
  Loop loop(ClockKind::Virtual);
  std::vector<int> order;
  for (int i = 0; i < 5; ++i) loop.after(1s, [&, i] { order.push_back(i); });
  loop.run();
  CHECK(order == std::vector<int>{0, 1, 2, 3, 4});
}

TEST_CASE("a cancelled timer never fires") {
  Loop loop(ClockKind::Virtual);
  bool fired = false;
  auto id = loop.after(1s, [&] { fired = true; });
  CHECK(loop.cancel(id));
  CHECK_FALSE(loop.cancel(id));
  loop.run();
  CHECK_FALSE(fired);
}

TEST_CASE("stop ends a virtual run that would otherwise go on forever") {
  Loop loop(ClockKind::Virtual);
  int ticks = 0;
  std::function<void()> tick = [&] {
    ++ticks;
    loop.after(100ms, tick);
  };
  loop.after(100ms, tick);
  loop.after(1s, [&] { loop.stop(); });
  loop.run();
  // ticks at 0.1 … 1.0 s; the one at exactly 1.0 s was scheduled before stop's own timer? No:
  // stop was scheduled at t=0, before the tick due at 1.0 s, so it fires first.
  CHECK(ticks == 9);
  CHECK(loop.seconds() == doctest::Approx(1.0));
}

TEST_CASE("posted work runs before virtual time moves") {
  Loop loop(ClockKind::Virtual);
  double postedAt = -1;
  loop.after(5s, [] {});
  loop.post([&] { postedAt = loop.seconds(); });
  loop.run();
  CHECK(postedAt == 0.0);
}

TEST_CASE("a real loop fires a timer after its delay and stops") {
  Loop loop(ClockKind::Real);
  double firedAt = -1;
  loop.after(20ms, [&] {
    firedAt = loop.seconds();
    loop.stop();
  });
  loop.run();
  CHECK(firedAt >= 0.020);
}

// Timer work that never catches up (docs/safety.md): signals, sockets and posted work still get
// their turn between bounded batches. The hog gives up after 200 rounds so that a loop without
// the bound fails the check instead of hanging.
TEST_CASE("a timer that is always overdue does not starve posted work (real clock)") {
  Loop loop(ClockKind::Real);
  int hogRounds = 0, roundsBeforePost = -1;
  std::function<void(TimePoint)> hog = [&](TimePoint due) {
    auto until = std::chrono::steady_clock::now() + 5ms;
    while (std::chrono::steady_clock::now() < until) {
    }
    if (++hogRounds < 200) loop.at(due + 1ms, [&hog, due] { hog(due + 1ms); });
  };
  loop.at(0ms, [&hog] { hog(0ms); });
  loop.after(1ms, [&] {
    loop.post([&] {
      roundsBeforePost = hogRounds;
      loop.stop();
    });
  });
  loop.run();
  CHECK(roundsBeforePost >= 0);
  CHECK(roundsBeforePost < 20);
}

TEST_CASE("a timer that reschedules itself for now does not starve posted work (virtual)") {
  Loop loop(ClockKind::Virtual);
  int rounds = 0, roundsBeforePost = -1;
  std::function<void()> again = [&] {
    if (++rounds < 100000) loop.after(0ms, again);
  };
  loop.after(0ms, again);
  loop.post([&] {
    loop.post([&] {
      roundsBeforePost = rounds;
      loop.stop();
    });
  });
  loop.run();
  CHECK(roundsBeforePost >= 0);
  CHECK(roundsBeforePost < 1000);
}

TEST_CASE("a virtual run calls its pass check once per pass, and may be stopped from it") {
  Loop loop(ClockKind::Virtual);
  std::vector<double> checkedAt;
  int fired = 0;
  for (int s = 1; s <= 5; ++s) loop.after(std::chrono::seconds(s), [&] { ++fired; });
  loop.setPassCheck([&] {
    checkedAt.push_back(loop.seconds());
    if (fired == 3) loop.stop();
  });
  loop.run();
  CHECK(fired == 3);               // stopped from the check: the timers at 4 s and 5 s wait
  CHECK(loop.seconds() == 3.0);    // and virtual time did not move on to them
  REQUIRE(checkedAt.size() >= 4);  // before each timer fired, and once after the third
  CHECK(checkedAt.front() == 0.0);
  loop.setPassCheck({});  // removed: the run goes on to the end
  loop.run();
  CHECK(fired == 5);
}

TEST_CASE("runAtMost ends at its limit or at stop(), and says which; runUntil leaves no timer") {
  Loop loop(ClockKind::Virtual);
  // nothing stops it: the limit does, at the limit's time
  loop.after(10s, [] {});
  CHECK_FALSE(loop.runAtMost(2s));
  CHECK(loop.seconds() == 2.0);
  CHECK(loop.pendingTimers() == 1);  // its own deadline is gone; the 10 s timer waits
  // a stop() before the limit: true, at the stop's time
  loop.after(1s, [&] { loop.stop(); });
  CHECK(loop.runAtMost(5s));
  CHECK(loop.seconds() == 3.0);
  CHECK(loop.pendingTimers() == 1);
  // runUntil: a condition that comes true, then one that never does
  bool flag = false;
  loop.after(500ms, [&] { flag = true; });
  CHECK(loop.runUntil([&] { return flag; }, 5s));
  CHECK(loop.seconds() == doctest::Approx(3.501).epsilon(0.001));
  CHECK_FALSE(loop.runUntil([] { return false; }, 1s));
  CHECK(loop.pendingTimers() == 1);  // only the 10 s timer: no poll, no deadline left behind
}
