// Gamepads on the host (engine/drive/gamepads.hpp), as far as a machine without input devices
// can tell: the folder's errors, nodes that are no gamepads looked at as they come and go
// (hot-plug), the folder read again when inotify loses events, a stale node told from a new one. A
// real kernel gamepad (uinput) plugged in and out drives a car in tests/qemu/gamepad_e2e.sh.
#include "engine/drive/gamepads.hpp"

#include <doctest/doctest.h>
#include <fcntl.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "engine/drive/seats.hpp"
#include "engine/fleet/fleet.hpp"

using namespace pitwall;
namespace fs = std::filesystem;

namespace {

struct Rig {
  Loop loop{ClockKind::Real};
  Fleet fleet{loop};
  drive::Seats seats{loop, fleet, 1};
  fs::path folder = fs::temp_directory_path() / ("pitwall-gamepads-" + std::to_string(::getpid()));
  Rig() { fs::create_directories(folder); }
  ~Rig() { fs::remove_all(folder); }
  void run(double seconds) {
    loop.after(fromSeconds(seconds), [this] { loop.stop(); });
    loop.run();
  }
};

}  // namespace

TEST_CASE("gamepads: a folder that is not there is an error naming it") {
  Rig r;
  drive::Gamepads pads(r.loop, r.seats, {r.folder / "nope"});
  auto started = pads.start();
  REQUIRE_FALSE(started);
  CHECK(started.error().find((r.folder / "nope").string() + " is not a folder") !=
        std::string::npos);
}

TEST_CASE("gamepads: $PITWALL_INPUT_DIR names the folder when the options name none") {
  Rig r;
  ::setenv("PITWALL_INPUT_DIR", r.folder.c_str(), 1);
  drive::Gamepads pads(r.loop, r.seats);
  auto started = pads.start();
  ::unsetenv("PITWALL_INPUT_DIR");
  REQUIRE(started);
  CHECK(pads.folder() == r.folder);
  CHECK(pads.count() == 0);
}

TEST_CASE("gamepads: event nodes that are no evdev devices, there or plugged in, are left alone") {
  Rig r;
  std::ofstream(r.folder / "event0") << "not a device";
  std::ofstream(r.folder / "mouse0") << "not an event node";
  drive::Gamepads pads(r.loop, r.seats, {r.folder});
  REQUIRE(pads.start());
  CHECK(pads.count() == 0);
  CHECK(pads.passedOver() == 1);  // event0 looked at; mouse0 is no event node
  // Hot-plug: a node created while running is looked at (inotify, IN_CREATE) …
  std::ofstream(r.folder / "event1") << "plugged in";
  fs::permissions(r.folder / "event1", fs::perms::owner_read);  // IN_ATTRIB
  r.run(0.1);
  CHECK(pads.passedOver() == 2);
  // … and one deleted is forgotten (IN_DELETE).
  fs::remove(r.folder / "event0");
  r.run(0.1);
  CHECK(pads.passedOver() == 1);
  CHECK(pads.count() == 0);
  CHECK_FALSE(r.seats.seat(1)->held());
}

TEST_CASE("gamepads: when inotify's queue overflows, the folder is read again") {
  std::ifstream limitFile("/proc/sys/fs/inotify/max_queued_events");
  long limit = 0;
  limitFile >> limit;
  if (limit <= 0 || limit > 200000) {
    MESSAGE("skipped: max_queued_events is " << limit);
    return;
  }
  Rig r;
  drive::Gamepads pads(r.loop, r.seats, {r.folder});
  REQUIRE(pads.start());
  CHECK(pads.passedOver() == 0);
  // The loop does not run: more events than the queue holds (two files in turn, so the kernel
  // cannot merge them), then a node whose IN_CREATE is lost with the rest.
  std::ofstream(r.folder / "a") << "";
  std::ofstream(r.folder / "b") << "";
  for (long i = 0; i <= limit; ++i)
    fs::permissions(r.folder / (i % 2 ? "a" : "b"),
                    i % 4 < 2 ? fs::perms::owner_read : fs::perms::owner_all);
  std::ofstream(r.folder / "event7") << "plugged in while the queue was full";
  r.run(0.2);
  CHECK(pads.passedOver() == 1);  // event7, found by reading the folder again
}

TEST_CASE("gamepads: sameNode tells an open node from one gone or made again under its name") {
  Rig r;
  const fs::path node = r.folder / "event3";
  std::ofstream(node) << "pad";
  int fd = ::open(node.c_str(), O_RDONLY | O_CLOEXEC);
  REQUIRE(fd >= 0);
  CHECK(drive::sameNode(fd, node.string()));
  fs::remove(node);
  CHECK_FALSE(drive::sameNode(fd, node.string()));  // unplugged
  std::ofstream(node) << "another pad";             // plugged in again: the same name
  CHECK_FALSE(drive::sameNode(fd, node.string()));
  ::close(fd);
  fd = ::open(node.c_str(), O_RDONLY | O_CLOEXEC);
  CHECK(drive::sameNode(fd, node.string()));
  ::close(fd);
  CHECK_FALSE(drive::sameNode(fd, node.string()));  // closed: POLLNVAL
}
