// A script error flood in the log (issue 14): a handler that fails on every event prints its
// traceback once, then a count line a second of engine time; pitwall.onError still sees every
// error; the counts still pending are logged when the world shuts down.
#include <doctest/doctest.h>

#include <regex>

#include "bindings/car_binding.hpp"
#include "bindings/interrupt.hpp"
#include "bindings/script_host.hpp"
#include "engine/core/log.hpp"
#include "tests/unit/capture_link.hpp"

using namespace pitwall;
using namespace std::chrono_literals;
using pitwall::testing::CaptureLink;

namespace {

struct FailingHandler {
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  CaptureLink* link = nullptr;
  std::unique_ptr<ScriptHost> host;
  std::vector<std::string> logged;

  FailingHandler() {
    // The car drives on (--handler-errors 0): these are about the log of a flood, not the stop
    // (tests/unit/bindings/handler_errors_test.cpp).
    auto l = std::make_unique<CaptureLink>();
    link = l.get();
    fleet.add(std::move(l), CarIdentity{0, "skull", 9, 1});
    link->setConnected(true);
    setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
    HostOptions options;
    options.handler_errors = {0, 10.0};
    host = std::make_unique<ScriptHost>(loop, fleet, nullptr, options);
    log::setTimeSource([this] { return loop.seconds(); });
    log::setSink([this](log::Level, std::string_view line) { logged.emplace_back(line); });
  }
  ~FailingHandler() {
    log::setSink(nullptr);
    log::setTimeSource(nullptr);
  }

  void start(const std::string& code) { REQUIRE(host->startString(code, "flood.lua")); }
  // `n` position updates from the car, one every `every` of engine time, then the run ends.
  void positions(int n, Duration every) {
    for (int i = 0; i < n; ++i)
      loop.after(every * i, [this, i] {
        anki::PositionUpdate m;
        m.location_id = static_cast<std::uint8_t>(i);
        m.piece_id = 39;
        link->carSends(m);
      });
    loop.after(every * n, [this] { host->shutDown(); });
    loop.run();
  }
  int countLines(const std::string& text) const {
    int n = 0;
    for (const auto& l : logged) n += l.find(text) != std::string::npos;
    return n;
  }
  // The N of every "… failed N more time(s): …" line.
  std::vector<long> counts(const std::string& where) const {
    std::vector<long> out;
    std::regex re(where + " failed ([0-9]+) more times?: ");
    std::smatch m;
    for (const auto& l : logged)
      if (std::regex_search(l, m, re)) out.push_back(std::stol(m[1]));
    return out;
  }
};

long sum(const std::vector<long>& v) {
  long s = 0;
  for (long x : v) s += x;
  return s;
}

}  // namespace

TEST_CASE_FIXTURE(FailingHandler,
                  "a handler failing on 1000 events prints one traceback and counts the rest") {
  start(R"(
    calls = 0
    pitwall.cars()[1].onPosition = function(car, ev)
      calls = calls + 1
      error("no lap yet at location " .. ev.location)
    end
  )");
  positions(1000, 10ms);  // 10 s of engine time
  lua_getglobal(host->state(), "calls");
  CHECK(lua_tointeger(host->state(), -1) == 1000);
  CHECK(countLines("stack traceback:") == 1);
  CHECK(countLines("error in onPosition handler of car 1 (skull): flood.lua:5: no lap yet") == 1);
  auto n = counts("onPosition handler of car 1 \\(skull\\)");
  CHECK(sum(n) == 999);
  CHECK(n.size() >= 10);  // one line a second of engine time, the last at shutdown
  // A count line quotes the first line of the latest error, and says when it was written.
  CHECK(logged.back().find("error script: onPosition handler of car 1 (skull) failed") !=
        std::string::npos);
  CHECK(logged.back().find(": flood.lua:5: no lap yet at location 231") != std::string::npos);
  CHECK(logged.back().find("stack traceback") == std::string::npos);
  CHECK(logged.size() == n.size() + 1);  // nothing else was logged
}

TEST_CASE_FIXTURE(FailingHandler, "after a quiet second, the next failure prints in full again") {
  start(R"(
    local n = 0
    pitwall.cars()[1].onPosition = function(car, ev)
      n = n + 1
      if n <= 5 or n > 300 then error("bad event " .. n) end
    end
  )");
  positions(310, 10ms);  // fails at 0–0.04 s, then from 3.0 s on: 5 + 10 failures
  CHECK(countLines("stack traceback:") == 2);
  CHECK(sum(counts("onPosition handler of car 1 \\(skull\\)")) == 4 + 9);
}

TEST_CASE_FIXTURE(FailingHandler, "pitwall.onError still takes every error") {
  start(R"(
    handled = 0
    pitwall.onError = function(text, where) handled = handled + 1 end
    pitwall.cars()[1].onPosition = function() error("no") end
  )");
  positions(1000, 10ms);
  lua_getglobal(host->state(), "handled");
  CHECK(lua_tointeger(host->state(), -1) == 1000);
  CHECK(logged.empty());
}

TEST_CASE_FIXTURE(FailingHandler, "the callback budget's interrupts are counted the same way") {
  host.reset();
  HostOptions options;
  options.budget = 5ms;
  options.handler_errors = {0, 10.0};  // as the fixture's: the car drives on
  host = std::make_unique<ScriptHost>(loop, fleet, nullptr, options);
  start(R"(
    pitwall.cars()[1].onPosition = function() while true do end end
  )");
  positions(20, 10ms);
  CHECK(countLines("still running after 5 ms: interrupted") == 2);  // the traceback, the count
  CHECK(countLines("stack traceback:") == 1);
  CHECK(sum(counts("onPosition handler of car 1 \\(skull\\)")) == 19);
}

TEST_CASE_FIXTURE(FailingHandler,
                  "two failing timers are two places, each named where it was written") {
  start(R"(
    pitwall.every(0.1, function() error("first") end)
    pitwall.every(0.1, function() error("second") end)
  )");
  positions(250, 10ms);  // until 2.5 s: ticks at 0.1 … 2.4 s, 24 failures of each
  CHECK(countLines("stack traceback:") == 2);
  CHECK(countLines("error in pitwall.every callback (flood.lua:2): flood.lua:2: first") == 1);
  CHECK(countLines("error in pitwall.every callback (flood.lua:3): flood.lua:3: second") == 1);
  CHECK(sum(counts("pitwall.every callback \\(flood.lua:2\\)")) == 23);
  CHECK(sum(counts("pitwall.every callback \\(flood.lua:3\\)")) == 23);
}
