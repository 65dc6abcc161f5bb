// Gamepads on the host (engine/drive/gamepads.hpp), as far as a machine without input devices
// can tell: the folder's errors, and nodes that are no gamepads left alone. A real kernel gamepad
// (uinput) plugged in and out drives a car in tests/qemu/gamepad_e2e.sh.
#include "engine/drive/gamepads.hpp"

#include <doctest/doctest.h>
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
  std::ofstream(r.folder / "event1") << "plugged in";
  fs::permissions(r.folder / "event1", fs::perms::owner_read);  // IN_ATTRIB
  fs::remove(r.folder / "event0");                              // IN_DELETE
  r.run(0.1);
  CHECK(pads.count() == 0);
  CHECK_FALSE(r.seats.seat(1)->held());
}
