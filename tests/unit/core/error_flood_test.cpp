// A flood of errors from one place: the first in full, then a count line a second (issue 14).
// Engine time on a virtual loop; the count lines are read from the log.
#include "engine/core/error_flood.hpp"

#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "engine/core/log.hpp"

using namespace pitwall;
using namespace std::chrono_literals;

namespace {
struct Flood {
  Loop loop{ClockKind::Virtual};
  ErrorFlood flood{loop, "script"};
  std::vector<std::string> lines;  // "[t] error script: …", with the engine time
  int printed = 0;                 // errors the caller was told to print in full
  Flood() {
    log::setTimeSource([this] { return loop.seconds(); });
    log::setSink([this](log::Level, std::string_view line) { lines.emplace_back(line); });
  }
  ~Flood() {
    log::setSink(nullptr);
    log::setTimeSource(nullptr);
  }
  // `n` errors from `where`, one every `every` of engine time from now.
  void fail(const std::string& where, int n, Duration every, const std::string& message) {
    for (int i = 0; i < n; ++i)
      loop.after(every * i, [this, where, message] {
        if (flood.admit(where, message)) ++printed;
      });
  }
};
}  // namespace

TEST_CASE_FIXTURE(Flood,
                  "the first error of a place is printed, the next are counted once a second") {
  fail("onPosition handler of car 2 (skull)", 250, 10ms,
       "skull.lua:3: no lap yet\nstack traceback:\n\t[C]: in function 'error'");
  loop.run();
  CHECK(printed == 1);
  // 249 more until 2.49 s, counted at 1 s (those of 0.01–1.00 s), 2 s and 3 s.
  REQUIRE(lines.size() == 3);
  CHECK(lines[0] ==
        "[    1.000] error script: onPosition handler of car 2 (skull) failed 100 more times: "
        "skull.lua:3: no lap yet");
  CHECK(lines[1].find("[    2.000] error script: onPosition handler of car 2 (skull) failed 100 "
                      "more times: ") == 0);
  CHECK(lines[2].find("[    3.000] error script: onPosition handler of car 2 (skull) failed 49 "
                      "more times: ") == 0);
}

TEST_CASE_FIXTURE(Flood, "after a quiet second the next error of that place is printed again") {
  fail("pitwall.every callback", 3, 100ms, "boom");
  loop.run();  // at 0: printed; 0.1, 0.2: counted
  fail("pitwall.every callback", 1, 0ms, "boom again");
  loop.run();
  CHECK(printed == 2);
  REQUIRE(lines.size() == 1);
  CHECK(lines[0].find("pitwall.every callback failed 2 more times: boom") != std::string::npos);
}

TEST_CASE_FIXTURE(Flood, "a second place is counted apart, and one error more is said so") {
  fail("onPosition handler of car 1 (groundshock)", 2, 10ms, "a");
  fail("onTransition handler of car 1 (groundshock)", 2, 10ms, "b");
  loop.run();
  CHECK(printed == 2);
  REQUIRE(lines.size() == 2);
  CHECK(lines[0].find("onPosition handler of car 1 (groundshock) failed 1 more time: a") !=
        std::string::npos);
  CHECK(lines[1].find("onTransition handler of car 1 (groundshock) failed 1 more time: b") !=
        std::string::npos);
}

TEST_CASE_FIXTURE(Flood, "counts still pending are logged when the flood is flushed") {
  fail("task race.lua:12", 5, 10ms, "first line\nsecond line");
  loop.after(500ms, [this] {
    flood.flush();
    loop.stop();
  });
  loop.run();
  REQUIRE(lines.size() == 1);
  CHECK(lines[0] == "[    0.500] error script: task race.lua:12 failed 4 more times: first line");
  CHECK(loop.pendingTimers() == 0);  // nothing of it is left on the loop
}
