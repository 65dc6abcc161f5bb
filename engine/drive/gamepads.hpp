#pragma once
// Gamepads on the host (docs/controllers.md): every evdev gamepad in a folder (/dev/input), as
// it is plugged in and out (hot-plug), takes the first free human seat (engine/drive/seats.hpp)
// and drives it: a trigger or the left stick for the throttle, the shoulder buttons for lanes.
// A gamepad that disappears lets go of its seat, which slows its car to a stop.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>

#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"
#include "engine/drive/seats.hpp"

namespace pitwall::drive {

struct GamepadsOptions {
  // Where the event nodes are. Empty: $PITWALL_INPUT_DIR when set (tests), else /dev/input —
  // read by start().
  std::filesystem::path folder;
};

class Gamepads {
 public:
  Gamepads(Loop& loop, Seats& seats, GamepadsOptions options = {});
  ~Gamepads();
  Gamepads(const Gamepads&) = delete;
  Gamepads& operator=(const Gamepads&) = delete;

  // Watches the folder and opens the gamepads in it now. The error names the folder and what to
  // do (no such folder; not readable: the user is not in group `input`).
  Result<bool, std::string> start();
  std::size_t count() const;       // gamepads open now
  std::size_t passedOver() const;  // event nodes looked at and found no gamepad (there now)
  const std::filesystem::path& folder() const;  // the folder watched (after start())

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The node at `path` is still the device `fd` has open: the kernel has not said it is gone (evdev
// polls POLLHUP | POLLERR for a device unplugged), and the node is the same inode — a pad plugged
// in again gets the same name and device number, but a new node. Checked for every open gamepad
// when inotify lost events (IN_Q_OVERFLOW); exposed for the tests.
bool sameNode(int fd, const std::string& path);

}  // namespace pitwall::drive
