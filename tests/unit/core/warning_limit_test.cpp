// A flood of warnings from one source: the first in full, then a count line every 5 s (issue
// 33). Engine time on a virtual loop; the lines are read from the log.
#include "engine/core/warning_limit.hpp"

#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "engine/core/log.hpp"
#include "engine/vehicles/anki_car.hpp"
#include "tests/unit/capture_link.hpp"

using namespace pitwall;
using namespace std::chrono_literals;

namespace {
struct Log {
  Loop loop{ClockKind::Virtual};
  std::vector<std::string> lines;  // "[t] warn component: …", with the engine time
  Log() {
    log::setTimeSource([this] { return loop.seconds(); });
    log::setSink([this](log::Level, std::string_view line) { lines.emplace_back(line); });
  }
  ~Log() {
    log::setSink(nullptr);
    log::setTimeSource(nullptr);
  }
  // `n` calls of `fn`, one every `every` of engine time from now.
  template <class F>
  void flood(int n, Duration every, F fn) {
    for (int i = 0; i < n; ++i) loop.after(every * i, [fn, i] { fn(i); });
  }
};
}  // namespace

TEST_CASE_FIXTURE(Log, "a warning flood: the first in full, then one count line every 5 s") {
  WarningLimit limit{loop, "malformed frames ignored"};
  // 1000 warnings a second for 12 s (the one due at 5 s comes before the count line due then:
  // it was scheduled first)
  flood(12'000, 1ms, [&](int i) {
    limit.warn("car 1 (skull)", "malformed frame ignored: frame " + std::to_string(i));
  });
  loop.run();
  REQUIRE(lines.size() == 4);
  CHECK(lines[0] == "[    0.000] warn car 1 (skull): malformed frame ignored: frame 0");
  CHECK(lines[1] ==
        "[    5.000] warn car 1 (skull): 5000 more malformed frames ignored in 5 s; "
        "the latest: malformed frame ignored: frame 5000");
  CHECK(lines[2] ==
        "[   10.000] warn car 1 (skull): 5000 more malformed frames ignored in 5 s; "
        "the latest: malformed frame ignored: frame 10000");
  CHECK(lines[3] ==
        "[   15.000] warn car 1 (skull): 1999 more malformed frames ignored in 5 s; "
        "the latest: malformed frame ignored: frame 11999");
  CHECK(limit.total() == 12'000);
  CHECK(limit.pending() == 0);
}

TEST_CASE_FIXTURE(Log, "after a quiet period the next warning is said in full again") {
  WarningLimit limit{loop, "malformed frames ignored"};
  limit.warn("car 1", "first");
  loop.after(1s, [&] { limit.warn("car 1", "second"); });
  loop.after(20s, [&] { limit.warn("car 1", "third"); });
  loop.run();
  REQUIRE(lines.size() == 3);
  CHECK(lines[0] == "[    0.000] warn car 1: first");
  CHECK(lines[1] ==
        "[    5.000] warn car 1: 1 more malformed frames ignored in 5 s; the latest: second");
  CHECK(lines[2] == "[   20.000] warn car 1: third");
}

TEST_CASE_FIXTURE(Log, "a count still pending when the limit goes is logged, not lost") {
  {
    WarningLimit limit{loop, "malformed frames ignored"};
    limit.warn("car 1", "first");
    limit.warn("car 1", "second");
    limit.warn("car 1", "third");
  }
  REQUIRE(lines.size() == 2);
  CHECK(lines[1] ==
        "[    0.000] warn car 1: 2 more malformed frames ignored in 5 s; the latest: third");
}

TEST_CASE_FIXTURE(Log, "a car sending only malformed frames: every one counted, few lines logged") {
  testing::CaptureLink link;
  AnkiCar car{loop, link, CarIdentity{1, "skull", 9, 42}};
  link.setConnected(true);
  int reported = 0;  // a script still hears every one (car.malformed)
  Subscription heard = car.malformed.connect(
      [&](const anki::DecodeError&, std::span<const std::uint8_t>) { ++reported; });
  // 100 000 bad frames over 10 s: 10 000 a second, a hostile peer's rate
  flood(100'000, 100us, [&](int) { link.carSendsBytes({0x10, 0x27, 0x01}); });
  loop.run();
  CHECK(car.state().malformed == 100'000);
  CHECK(reported == 100'000);
  std::size_t warned = 0;
  for (const auto& line : lines) warned += line.find("malformed frame") != std::string::npos;
  CHECK(warned == 3);  // the first, and a count at 5 s and at 10 s
  REQUIRE(!lines.empty());
  CHECK(lines[0].find("malformed frame ignored: ") != std::string::npos);
  CHECK(lines.back().find(" more malformed frames ignored in 5 s; the latest: ") !=
        std::string::npos);
}
