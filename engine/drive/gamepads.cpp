#include "engine/drive/gamepads.hpp"

#include <fcntl.h>
#include <libevdev/libevdev.h>
#include <poll.h>
#include <sys/inotify.h>
#include <sys/stat.h>
#include <unistd.h>

#include <boost/asio/posix/stream_descriptor.hpp>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <system_error>
#include <vector>

#include "engine/core/inotify.hpp"
#include "engine/core/log.hpp"
#include "engine/core/printable.hpp"
#include "engine/drive/gamepad_mapping.hpp"

namespace pitwall::drive {

namespace fs = std::filesystem;
using boost::asio::posix::stream_descriptor;

namespace {
constexpr const char* kLog = "gamepads";
// A node appears (IN_CREATE) before udev has set its group and mode (IN_ATTRIB): a node that
// cannot be opened yet is tried again on IN_ATTRIB. IN_DELETE: unplugged. The moves are for a
// test folder that gets its nodes by rename.
constexpr std::uint32_t kMask = IN_CREATE | IN_ATTRIB | IN_DELETE | IN_MOVED_TO | IN_MOVED_FROM;

bool isEventNode(const std::string& name) {
  return name.rfind("event", 0) == 0;
}
std::string errnoText(int e) {
  return std::strerror(e);
}

struct EvdevFree {
  void operator()(libevdev* d) const { libevdev_free(d); }
};

DeviceCaps capsOf(const libevdev* dev) {
  DeviceCaps caps;
  for (int code = 0; code <= KEY_MAX; ++code)
    if (libevdev_has_event_code(dev, EV_KEY, static_cast<unsigned>(code))) caps.keys.insert(code);
  for (int code = 0; code <= ABS_MAX; ++code) {
    if (!libevdev_has_event_code(dev, EV_ABS, static_cast<unsigned>(code))) continue;
    if (const input_absinfo* a = libevdev_get_abs_info(dev, static_cast<unsigned>(code)))
      caps.axes[code] = AxisInfo{a->minimum, a->maximum, a->flat, a->value};
  }
  return caps;
}

std::string axisName(int code) {
  const char* name = libevdev_event_code_get_name(EV_ABS, static_cast<unsigned>(code));
  return name ? name : "ABS_" + std::to_string(code);
}

std::string throttleText(const GamepadMapping& m) {
  if (m.triggerArmed()) return "throttle on " + axisName(m.triggerAxis());
  return "throttle on the left stick (up) or BTN_TR2";
}

}  // namespace

bool sameNode(int fd, const std::string& path) {
  pollfd p{fd, POLLIN, 0};
  if (::poll(&p, 1, 0) < 0 || (p.revents & (POLLHUP | POLLERR | POLLNVAL))) return false;
  struct stat held {
  }, there{};
  if (::fstat(fd, &held) < 0 || ::stat(path.c_str(), &there) < 0) return false;
  return held.st_dev == there.st_dev && held.st_ino == there.st_ino &&
         held.st_rdev == there.st_rdev;
}

struct Gamepads::Impl {
  struct Device {
    Device(boost::asio::io_context& io, int fd) : stream(io, fd) {}
    std::string path;  // also the seat's holder
    std::string name;
    stream_descriptor stream;  // owns the fd
    std::unique_ptr<libevdev, EvdevFree> evdev;
    std::optional<GamepadMapping> mapping;
    bool seated = false;
  };

  Impl(Loop& loop, Seats& seats, GamepadsOptions options)
      : loop(loop), seats(seats), options(std::move(options)) {}

  ~Impl() {
    *alive = false;
    watchSeats.disconnect();
    // Each gamepad lets go of its seat: its car is slowed to a stop (a run that ends has stopped
    // its cars already; this is the same stop again).
    for (auto& [path, device] : devices)
      if (device->seated) seats.release(path, "the gamepads stop");
    devices.clear();
  }

  Result<bool, std::string> start();
  void scan();
  void overflowed();
  void folderEvent(std::uint32_t mask, const std::string& name);
  void open(const std::string& path);
  void seat(Device& device);
  void seatWaiting();
  void waitDevice(const std::shared_ptr<Device>& device);
  void readDevice(const std::shared_ptr<Device>& device);
  void drop(const std::string& path, const std::string& why);

  Loop& loop;
  Seats& seats;
  GamepadsOptions options;
  std::unique_ptr<Inotify> inotify;
  std::map<std::string, std::shared_ptr<Device>> devices;
  std::set<std::string> notGamepads;  // nodes opened once and found no gamepad: not again
  std::set<std::string> refused;      // nodes we may not open (permissions) — for the hint
  bool warnedFull = false;
  Subscription watchSeats;
  std::shared_ptr<bool> alive = std::make_shared<bool>(true);
};

Result<bool, std::string> Gamepads::Impl::start() {
  if (options.folder.empty()) {
    const char* env = std::getenv("PITWALL_INPUT_DIR");
    options.folder = env && *env ? fs::path(env) : fs::path("/dev/input");
  }
  const std::string folder = options.folder.string();
  std::error_code ec;
  if (!fs::is_directory(options.folder, ec))
    return Unexpected(
        "no gamepads: " + folder + " is not a folder" +
        (ec ? " (" + ec.message() + ")" : std::string()) +
        "; is this a Linux host with evdev? ($PITWALL_INPUT_DIR names another folder)");
  auto made = Inotify::open(loop);
  if (!made) return Unexpected("no gamepads: cannot watch " + folder + ": " + made.error());
  inotify = std::move(made).value();
  if (auto wd = inotify->add(folder, kMask); !wd)
    return Unexpected("no gamepads: cannot watch " + folder + ": " + wd.error() +
                      (wd.error() == errnoText(EACCES)
                           ? " (add the user to group `input`, docs/controllers.md)"
                           : ""));
  // One folder is watched: every event is about it.
  inotify->onEvent = [this](int, std::uint32_t mask, const std::string& name) {
    folderEvent(mask, name);
  };
  inotify->onOverflow = [this] { overflowed(); };  // events lost: look at the folder again
  watchSeats = seats.changed.connect([this](const Seat& s) {
    if (!s.held()) seatWaiting();
  });
  scan();
  if (devices.empty() && !refused.empty())
    log::warn(kLog, "no gamepad in " + folder + " can be read: " + std::to_string(refused.size()) +
                        " event nodes refuse this user (permission denied); add it to group "
                        "`input` (docs/controllers.md), or plug a gamepad in: a new one is opened");
  else if (devices.empty())
    log::info(kLog, "no gamepad in " + folder + " yet: plug one in");
  return true;
}

void Gamepads::Impl::scan() {
  // The error_code overloads only: a folder that goes away or fails half way through is a
  // warning, never an exception out of the loop.
  std::error_code ec;
  std::set<std::string> names;
  for (fs::directory_iterator it(options.folder, ec), end; !ec && it != end; it.increment(ec))
    if (isEventNode(it->path().filename().string())) names.insert(it->path().string());
  if (ec) log::warn(kLog, "cannot list " + options.folder.string() + ": " + ec.message());
  for (const auto& path : names) open(path);  // sorted: event2 before event3, a stable order
}

// inotify's queue overflowed (IN_Q_OVERFLOW): unplugs and plug-ins may have been lost. A gamepad
// whose node is gone or is another device now is dropped — else a pad plugged in again under the
// same name would be passed over as already open — and nodes passed over are looked at again (a
// keyboard's node may be a gamepad's now); then the folder is read afresh.
void Gamepads::Impl::overflowed() {
  log::debug(kLog, "inotify's queue overflowed: looking at " + options.folder.string() + " again");
  std::weak_ptr<bool> weak = alive;
  std::vector<std::string> gone;
  for (const auto& [path, device] : devices)
    if (!sameNode(device->stream.native_handle(), path)) gone.push_back(path);
  for (const auto& path : gone) {
    drop(path, "the gamepad was unplugged");
    if (weak.expired()) return;
  }
  notGamepads.clear();
  refused.clear();
  scan();
}

void Gamepads::Impl::folderEvent(std::uint32_t mask, const std::string& name) {
  if (mask & IN_IGNORED) {
    log::warn(kLog, options.folder.string() + " is gone: no new gamepad will be seen");
    return;
  }
  if (name.empty() || !isEventNode(name)) return;
  const std::string path = (options.folder / name).string();
  if (mask & (IN_DELETE | IN_MOVED_FROM)) {
    notGamepads.erase(path);
    refused.erase(path);
    drop(path, "the gamepad was unplugged");
  } else if (!devices.count(path) && !notGamepads.count(path)) {
    open(path);  // IN_CREATE, or IN_ATTRIB once udev let us read it
  }
}

void Gamepads::Impl::open(const std::string& path) {
  if (devices.count(path)) return;
  int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    // EACCES: udev has not given it its group yet (IN_ATTRIB will say), or it is no device of
    // ours (a keyboard readable by root only). ENOENT: gone already.
    if (errno == EACCES || errno == EPERM) refused.insert(path);
    log::debug(kLog, "cannot open " + path + " yet: " + errnoText(errno));
    return;
  }
  refused.erase(path);
  libevdev* raw = nullptr;
  if (int rc = libevdev_new_from_fd(fd, &raw); rc < 0) {
    ::close(fd);
    log::debug(kLog, path + " is no evdev device: " + errnoText(-rc));
    notGamepads.insert(path);
    return;
  }
  std::unique_ptr<libevdev, EvdevFree> evdev(raw);
  const DeviceCaps caps = capsOf(evdev.get());
  if (!isGamepad(caps)) {
    ::close(fd);
    notGamepads.insert(path);
    return;
  }
  auto device = std::make_shared<Device>(loop.io(), fd);
  device->path = path;
  const char* name = libevdev_get_name(evdev.get());
  device->name = printable(name && *name ? name : "gamepad", 40);
  device->evdev = std::move(evdev);
  device->mapping.emplace(caps);
  devices[path] = device;
  log::info(kLog, "gamepad \"" + device->name + "\" at " + path + ": " +
                      throttleText(*device->mapping) + ", BTN_TL/BTN_TR lanes, BTN_SOUTH brakes");
  if (const auto& m = *device->mapping;
      m.source() == ThrottleSource::Trigger && !m.triggerArmed()) {
    const AxisInfo& a = caps.axes.at(m.triggerAxis());
    log::warn(kLog, "gamepad \"" + device->name + "\": " + axisName(m.triggerAxis()) +
                        " does not rest at its minimum (" + std::to_string(a.value) + " in " +
                        std::to_string(a.minimum) + ".." + std::to_string(a.maximum) +
                        "; a stick or a pedal, not a trigger?): it is not the throttle until it "
                        "does (docs/controllers.md)");
  }
  seat(*device);
  waitDevice(device);
}

void Gamepads::Impl::seat(Device& device) {
  if (device.seated) return;
  auto got = seats.claim(device.path, Holder::Gamepad, 0, device.name);
  if (!got) {
    if (!warnedFull)
      log::warn(kLog, "gamepad \"" + device.name + "\" waits for a seat: " + got.error());
    warnedFull = true;
    return;
  }
  device.seated = true;
  warnedFull = false;
  log::info(kLog, "gamepad \"" + device.name + "\" drives car " + std::to_string(got.value()));
}

// A seat was freed: the gamepads that wait take the free seats, first plugged in first.
void Gamepads::Impl::seatWaiting() {
  for (auto& [path, device] : devices)
    if (!device->seated) seat(*device);
}

void Gamepads::Impl::waitDevice(const std::shared_ptr<Device>& device) {
  std::weak_ptr<Device> weak = device;
  device->stream.async_wait(stream_descriptor::wait_read,
                            [this, weak](const boost::system::error_code& ec) {
                              auto d = weak.lock();
                              if (!d || ec == boost::asio::error::operation_aborted) return;
                              readDevice(d);
                            });
}

void Gamepads::Impl::readDevice(const std::shared_ptr<Device>& device) {
  // libevdev reads the fd until it is empty (it is non-blocking: -EAGAIN). After SYN_DROPPED
  // (the kernel's buffer overflowed, events lost) libevdev_next_event says SYNC and then hands
  // out the events that bring its state up to date, until -EAGAIN again (libevdev's docs,
  // "SYN_DROPPED handling").
  unsigned flags = LIBEVDEV_READ_FLAG_NORMAL;
  for (;;) {
    input_event ev{};
    int rc = libevdev_next_event(device->evdev.get(), flags, &ev);
    if (rc == -EAGAIN) {
      if (flags == LIBEVDEV_READ_FLAG_SYNC) {
        flags = LIBEVDEV_READ_FLAG_NORMAL;  // in sync again: go on reading
        continue;
      }
      break;
    }
    if (rc < 0) {
      drop(device->path, rc == -ENODEV ? std::string("the gamepad was unplugged")
                                       : "the gamepad cannot be read: " + errnoText(-rc));
      return;
    }
    if (rc == LIBEVDEV_READ_STATUS_SYNC && flags == LIBEVDEV_READ_FLAG_NORMAL) {
      log::debug(kLog, device->path + ": events dropped by the kernel; resynchronizing");
      flags = LIBEVDEV_READ_FLAG_SYNC;
      continue;  // this event is the SYN_DROPPED itself
    }
    const bool armed = device->mapping->triggerArmed();
    auto input =
        device->mapping->event(ev.type, ev.code, ev.value, flags == LIBEVDEV_READ_FLAG_SYNC);
    if (!armed && device->mapping->triggerArmed())
      log::info(kLog, "gamepad \"" + device->name +
                          "\": " + axisName(device->mapping->triggerAxis()) +
                          " rests at its minimum: it is the throttle from now on");
    if (input && device->seated) {
      auto sent = seats.input(device->path, input->throttle, input->laneStep);
      if (!sent) log::debug(kLog, device->path + ": " + sent.error());
    }
    if (!devices.count(device->path)) return;  // dropped meanwhile (a seat's listener)
  }
  waitDevice(device);
}

void Gamepads::Impl::drop(const std::string& path, const std::string& why) {
  auto it = devices.find(path);
  if (it == devices.end()) return;
  std::shared_ptr<Device> device = it->second;  // alive until this returns
  devices.erase(it);
  boost::system::error_code ec;
  device->stream.cancel(ec);
  log::info(kLog, "gamepad \"" + device->name + "\" at " + path + ": " + why);
  if (device->seated) seats.release(path, why);  // may seat a waiting gamepad at once
  device->evdev.reset();
  device->stream.close(ec);
}

Gamepads::Gamepads(Loop& loop, Seats& seats, GamepadsOptions options)
    : impl_(std::make_unique<Impl>(loop, seats, std::move(options))) {}

Gamepads::~Gamepads() = default;

Result<bool, std::string> Gamepads::start() {
  return impl_->start();
}

std::size_t Gamepads::count() const {
  return impl_->devices.size();
}

std::size_t Gamepads::passedOver() const {
  return impl_->notGamepads.size();
}

const fs::path& Gamepads::folder() const {
  return impl_->options.folder;
}

}  // namespace pitwall::drive
