// Programs beside the loop (engine/core/child_runs.hpp): the code page's Tests. What they wrote and
// how they ended reach the loop; one that runs past its time or writes past the cap is killed; at
// most `parallel` run at once, the rest wait in a bounded queue; the loop turns meanwhile.
#include <doctest/doctest.h>

#include <fcntl.h>
#include <unistd.h>

#include <optional>

#include "engine/core/child_runs.hpp"
#include "engine/core/loop.hpp"

using namespace pitwall;

namespace {

std::vector<std::string> sh(const std::string& script) {
  return {"/bin/sh", "-c", script};
}

}  // namespace

TEST_CASE("child runs: output, status, and the loop turns while a child runs") {
  Loop loop(ClockKind::Real);
  ChildRuns runs(loop, {});
  std::optional<ChildOutcome> got;
  REQUIRE(runs.run(sh("echo out; echo err >&2; sleep 0.2; exit 3"),
                   [&](ChildOutcome o) { got = std::move(o); }));
  int ticks = 0;
  loop.after(std::chrono::milliseconds(10), [&] {});
  std::function<void()> tick = [&] {
    ++ticks;
    if (!got) loop.after(std::chrono::milliseconds(10), tick);
  };
  tick();
  REQUIRE(loop.runUntil([&] { return got.has_value(); }, std::chrono::seconds(10)));
  CHECK(got->status == 3);
  CHECK(got->out == "out\n");
  CHECK(got->err == "err\n");
  CHECK_FALSE(got->timedOut);
  CHECK(got->seconds >= 0.2);
  CHECK(ticks >= 5);  // the loop went on while the child slept
  CHECK(runs.running() == 0);
}

TEST_CASE("child runs: past its time or past the output's cap, a child is killed") {
  Loop loop(ClockKind::Real);
  ChildLimits limits;
  limits.timeout = std::chrono::milliseconds(300);
  limits.maxOutput = 1000;
  ChildRuns runs(loop, limits);
  std::optional<ChildOutcome> slow, loud;
  // a child of the child too: the whole group goes
  REQUIRE(runs.run(sh("sleep 30 & sleep 30; echo never"),
                   [&](ChildOutcome o) { slow = std::move(o); }));
  REQUIRE(runs.run(sh("while true; do echo xxxxxxxxxxxxxxxxxxxxxxxx; done"),
                   [&](ChildOutcome o) { loud = std::move(o); }));
  REQUIRE(loop.runUntil([&] { return slow && loud; }, std::chrono::seconds(10)));
  CHECK(slow->timedOut);
  CHECK(slow->status == -1);
  CHECK(slow->out.empty());
  CHECK(loud->tooLong);
  CHECK(loud->out.size() == 1000);
}

TEST_CASE("child runs: at most `parallel` at once, a bounded queue, a missing program said") {
  Loop loop(ClockKind::Real);
  ChildLimits limits;
  limits.parallel = 1;
  limits.queue = 2;
  ChildRuns runs(loop, limits);
  std::vector<ChildOutcome> done;
  for (int k = 0; k < 3; ++k)
    REQUIRE(runs.run(sh("sleep 0.1; echo " + std::to_string(k)),
                     [&](ChildOutcome o) { done.push_back(std::move(o)); }));
  CHECK(runs.running() == 1);
  CHECK(runs.queued() == 2);
  CHECK_FALSE(runs.run(sh("true"), [](ChildOutcome) {}));  // the queue is full
  std::optional<ChildOutcome> missing;
  REQUIRE(loop.runUntil([&] { return done.size() == 3; }, std::chrono::seconds(10)));
  CHECK(done[0].out == "0\n");
  CHECK(done[2].out == "2\n");
  CHECK(done[2].waited >= 0.15);  // it waited for the two before it
  REQUIRE(runs.run({"/nonexistent/program"}, [&](ChildOutcome o) { missing = std::move(o); }));
  REQUIRE(loop.runUntil([&] { return missing.has_value(); }, std::chrono::seconds(10)));
  CHECK(missing->status == -1);  // glibc's posix_spawn says the exec failed: not started
  CHECK(missing->failure.find("/nonexistent/program") != std::string::npos);
}

TEST_CASE(
    "child runs: a child sees none of the run's descriptors; one that escapes its group "
    "does not hold the slot") {
  Loop loop(ClockKind::Real);
  ChildLimits limits;
  limits.timeout = std::chrono::milliseconds(300);
  ChildRuns runs(loop, limits);
  // a descriptor of the run's without close-on-exec (as Boost.Asio's sockets are)
  const int fd = ::open("/dev/null", O_RDONLY);
  REQUIRE(fd > 2);
  std::optional<ChildOutcome> fds, escaped;
  REQUIRE(runs.run(sh("ls /proc/$$/fd"), [&](ChildOutcome o) { fds = std::move(o); }));
  // a grandchild in a session of its own keeps the pipes open past the group's kill
  REQUIRE(
      runs.run(sh("setsid sleep 3 & sleep 30"), [&](ChildOutcome o) { escaped = std::move(o); }));
  const auto began = std::chrono::steady_clock::now();
  REQUIRE(loop.runUntil([&] { return fds && escaped; }, std::chrono::seconds(10)));
  ::close(fd);
  CHECK(fds->out == "0\n1\n2\n");
  CHECK(escaped->timedOut);
  CHECK(std::chrono::steady_clock::now() - began < std::chrono::milliseconds(2500));
  CHECK(runs.running() == 0);
}
