#include "engine/core/stop_signals.hpp"

#include <doctest/doctest.h>

#include <sys/socket.h>
#include <unistd.h>

#include <csignal>
#include <utility>
#include <vector>

using namespace pitwall;
using namespace std::chrono_literals;

// A virtual loop never sleeps, so StopSignals keeps no read pending on it: the handler's count
// is looked at on every pass (Loop::setPassCheck). The signal must reach onSignal all the same,
// at the virtual time it came, and before any later timer.
TEST_CASE("stop signals reach a virtual run on its next pass, before later timers") {
  Loop loop(ClockKind::Virtual);
  StopSignals signals(loop);
  std::vector<std::pair<int, int>> got;
  double at = -1;
  bool later = false;
  signals.onSignal = [&](int sig, int count) {
    got.emplace_back(sig, count);
    at = loop.seconds();
    if (count == 2) loop.stop();
  };
  loop.after(1s, [] { std::raise(SIGTERM); });
  loop.after(2s, [] { std::raise(SIGTERM); });
  loop.after(3s, [&] { later = true; });
  loop.run();
  CHECK(got == std::vector<std::pair<int, int>>{{SIGTERM, 1}, {SIGTERM, 2}});
  CHECK(at == 2.0);
  CHECK_FALSE(later);
}

namespace {
// Signals raised at the given times (ms) into a real run with StopSignals: what onSignal got, as
// sig * 100 + count each, until `last` arrives (or the test's own bound of 20 s, not expected).
std::vector<int> signalsSeen(const std::vector<std::pair<int, int>>& raised, int last) {
  Loop loop(ClockKind::Real);
  StopSignals signals(loop);
  std::vector<int> got;
  signals.onSignal = [&](int sig, int count) {
    got.push_back(sig * 100 + count);
    if (sig == last) loop.stop();
  };
  for (auto [ms, sig] : raised)
    loop.after(std::chrono::milliseconds(ms), [sig = sig] { std::raise(sig); });
  auto guard = loop.after(20s, [&] { loop.stop(); });
  loop.run();
  loop.cancel(guard);
  return got;
}
}  // namespace

TEST_CASE("stop signals reach a real run through the pipe") {
  CHECK(signalsSeen({{10, SIGTERM}}, SIGTERM) == std::vector<int>{SIGTERM * 100 + 1});
}

// A terminal that closes (a window shut, SSH dropped) sends SIGHUP, whose default action ends the
// process with no stop for any car: it ends the run as SIGTERM does. Ignored before (nohup), it
// stays ignored. Afterwards the handler that was there comes back.
TEST_CASE("SIGHUP ends a run as SIGTERM does, unless it was ignored (nohup)") {
  // as a terminal's shell starts a run: a test run started under nohup inherits SIGHUP ignored
  struct sigaction inherited {};
  ::sigaction(SIGHUP, nullptr, &inherited);
  std::signal(SIGHUP, SIG_DFL);
  struct sigaction before {};
  ::sigaction(SIGHUP, nullptr, &before);
  CHECK(signalsSeen({{10, SIGHUP}}, SIGHUP) == std::vector<int>{SIGHUP * 100 + 1});
  // a hang-up comes twice (the shell's and the kernel's): the repeat is no second signal; a real
  // second signal still counts
  CHECK(signalsSeen({{10, SIGHUP}, {10, SIGHUP}, {200, SIGTERM}}, SIGTERM) ==
        std::vector<int>{SIGHUP * 100 + 1, SIGTERM * 100 + 2});
  struct sigaction after {};
  ::sigaction(SIGHUP, nullptr, &after);
  CHECK((after.sa_handler == before.sa_handler));

  std::signal(SIGHUP, SIG_IGN);
  {
    Loop loop(ClockKind::Real);
    StopSignals signals(loop);
    struct sigaction during {};
    ::sigaction(SIGHUP, nullptr, &during);
    CHECK((during.sa_handler == SIG_IGN));
  }
  ::sigaction(SIGHUP, &inherited, nullptr);
}

// SIGTSTP (Ctrl-Z) reaches the loop, which stops the cars before it suspends the process; it is
// not a stop signal's count: a Ctrl-C after it is a first one.
TEST_CASE("SIGTSTP reaches the loop with count 0 and does not count towards leaving") {
  CHECK(signalsSeen({{10, SIGTSTP}, {100, SIGTERM}}, SIGTERM) ==
        std::vector<int>{SIGTSTP * 100 + 0, SIGTERM * 100 + 1});
}

// SIGPIPE counts only when stdout's or stderr's reader went away: a socket that meets a closed
// peer (a library writing without MSG_NOSIGNAL) ends nothing, and the process survives it.
TEST_CASE("SIGPIPE from a socket is not a reader going away") {
  Loop loop(ClockKind::Real);
  StopSignals signals(loop);
  std::vector<int> got;
  signals.onSignal = [&](int sig, int count) {
    got.push_back(sig * 100 + count);
    if (sig == SIGTERM) loop.stop();
  };
  int fds[2];
  REQUIRE(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds) == 0);
  ::close(fds[1]);
  loop.after(10ms, [&] {
    char byte = 1;
    CHECK(::write(fds[0], &byte, 1) == -1);  // SIGPIPE, then EPIPE
    CHECK(errno == EPIPE);
  });
  loop.after(100ms, [] { std::raise(SIGTERM); });
  loop.run();
  ::close(fds[0]);
  CHECK(got == std::vector<int>{SIGTERM * 100 + 1});
}
