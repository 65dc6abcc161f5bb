// The inotify instance shared by hot reload and gamepad hot-plug: real folders in /tmp, a
// real-clock loop.
#include "engine/core/inotify.hpp"

#include <doctest/doctest.h>
#include <sys/inotify.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "tests/support/run_until.hpp"
#include "tests/support/temp_dir.hpp"

using namespace pitwall;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {
struct Rig {
  Loop loop{ClockKind::Real};
  pitwall::testing::TempDir temp{"pitwall-inotify"};
  fs::path dir = temp.path;
  std::unique_ptr<Inotify> inotify;
  struct Seen {
    int wd;
    std::uint32_t mask;
    std::string name;
  };
  std::vector<Seen> events;
  int overflows = 0;
  Rig() {
    auto made = Inotify::open(loop);
    REQUIRE(made);
    inotify = std::move(made).value();
    inotify->onEvent = [this](int wd, std::uint32_t mask, const std::string& name) {
      events.push_back({wd, mask, name});
    };
    inotify->onOverflow = [this] { ++overflows; };
  }
};
}  // namespace

TEST_CASE("inotify: a file created in a watched folder is an event with its name") {
  Rig r;
  auto wd = r.inotify->add(r.dir.string(), IN_CREATE);
  REQUIRE(wd);
  std::ofstream(r.dir / "race.lua") << "print(1)";
  REQUIRE(testing::runUntil(r.loop, [&] { return !r.events.empty(); }));
  CHECK(r.events[0].wd == *wd);
  CHECK((r.events[0].mask & IN_CREATE) != 0);
  CHECK(r.events[0].name == "race.lua");
  CHECK(r.overflows == 0);
}

TEST_CASE("inotify: a folder that is not there cannot be watched, and says why") {
  Rig r;
  auto wd = r.inotify->add((r.dir / "nope").string(), IN_CREATE);
  REQUIRE_FALSE(wd);
  CHECK(wd.error() == "No such file or directory");
}

TEST_CASE("inotify: a watch destroyed by its own callback reads no further") {
  Rig r;
  REQUIRE(r.inotify->add(r.dir.string(), IN_CREATE));
  int calls = 0;
  r.inotify->onEvent = [&](int, std::uint32_t, const std::string&) {
    ++calls;
    r.inotify.reset();  // as an owner destroyed inside the callback
  };
  // Both events are queued before the loop runs: one read brings both.
  std::ofstream(r.dir / "a") << "";
  std::ofstream(r.dir / "b") << "";
  testing::runFor(r.loop, 100ms);
  CHECK(calls == 1);
  CHECK_FALSE(r.inotify);
}

TEST_CASE("inotify: an overflow of the kernel's queue on a watched folder is reported") {
  long limit = 0;
  std::ifstream("/proc/sys/fs/inotify/max_queued_events") >> limit;
  if (limit <= 0 || limit > 200000) {
    MESSAGE("skipped: max_queued_events is " << limit);
    return;
  }
  Rig r;
  REQUIRE(r.inotify->add(r.dir.string(), IN_ATTRIB));
  // The loop does not run: more events than the queue holds (two files in turn, so the kernel
  // cannot merge them).
  std::ofstream(r.dir / "a") << "";
  std::ofstream(r.dir / "b") << "";
  for (long i = 0; i <= limit; ++i)
    fs::permissions(r.dir / (i % 2 ? "a" : "b"),
                    i % 4 < 2 ? fs::perms::owner_read : fs::perms::owner_all);
  REQUIRE(testing::runUntil(
      r.loop, [&] { return r.overflows > 0; }, 10s));
  CHECK(r.overflows == 1);
  CHECK(r.events.size() == static_cast<std::size_t>(limit));  // all the queue held, then the loss
}
