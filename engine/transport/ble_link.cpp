#include "engine/transport/ble_link.hpp"

#include <sys/socket.h>

#include <sdbus-c++/sdbus-c++.h>
#include <cerrno>
#include <cstring>

#include "engine/core/log.hpp"

namespace pitwall::ble {

namespace {
std::string seconds(Duration d) {
  auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(d).count();
  return ms % 1000 == 0 ? std::to_string(ms / 1000) + " s" : std::to_string(ms) + " ms";
}
}  // namespace

BleLink::BleLink(Bluez& bluez, std::string devicePath, std::string address, LinkTimeouts timeouts)
    : bluez_(bluez),
      devicePath_(std::move(devicePath)),
      address_(std::move(address)),
      timeouts_(timeouts),
      notifyFd_(bluez.loop().io()),
      writeFd_(bluez.loop().io()),
      alive_(std::make_shared<bool>(true)) {}

BleLink::~BleLink() {
  *alive_ = false;
  bluez_.loop().cancel(stepTimer_);
  closeChannels();
}

void BleLink::armStepTimer(Duration timeout, std::string what) {
  bluez_.loop().cancel(stepTimer_);
  auto attempt = attempt_;
  stepTimer_ = bluez_.loop().after(timeout, [this, attempt, timeout, what] {
    stepTimer_ = 0;
    if (current(attempt)) fail(what + " timed out after " + seconds(timeout));
  });
}

void BleLink::connect(Done done) {
  if (step_ != Step::Idle) {
    if (done)
      done(step_ == Step::Up ? std::nullopt : std::optional<std::string>("already connecting"));
    return;
  }
  auto attempt = ++attempt_;
  done_ = std::move(done);
  disconnectRequested_ = false;
  abandonedConnect_ = false;
  step_ = Step::Connecting;
  std::weak_ptr<bool> alive = alive_;
  log::debug(address(), "connecting");
  bluez_.proxy(devicePath_)
      .callMethodAsync("Connect")
      .onInterface(kDeviceIface)
      .withTimeout(timeouts_.connect)
      .uponReplyInvoke([this, alive, attempt](const sdbus::Error* error) {
        if (alive.expired()) return;
        if (!current(attempt)) {
          if (!error && step_ == Step::Idle) disconnectQuietly();  // given up, yet connected
          return;
        }
        if (error && error->getName() != "org.bluez.Error.AlreadyConnected")
          return fail(describe(*error, "connecting to " + address_));
        step_ = Step::Resolving;
        const Device* d = bluez_.device(devicePath_);
        sawConnected_ = d && d->connected;
        if (d && d->servicesResolved) return resolved();
        armStepTimer(timeouts_.resolve, "service discovery on " + address_);
      });
  bluez_.pump().kick();
}

void BleLink::deviceChanged(const Device& d) {
  // A loss is Connected going from true to false. BlueZ may answer Connect before its
  // Connected=true signal arrives: a false seen before any true is not a loss.
  bool wasConnected = sawConnected_;
  sawConnected_ = d.connected;
  if (step_ == Step::Idle) {
    // A Connect given up on (sd-bus drops a reply that comes after the call's timeout) may
    // still succeed: hang up, or the car stays taken and invisible to the next scan.
    if (abandonedConnect_ && d.connected) {
      abandonedConnect_ = false;
      disconnectQuietly();
    }
    return;
  }
  if (!d.connected && wasConnected && step_ != Step::Connecting) {
    if (step_ == Step::Up)
      lost(address_ + " disconnected");
    else
      fail(address_ + " disconnected during " +
           (step_ == Step::Resolving ? "service discovery" : "setup"));
    return;
  }
  if (step_ == Step::Resolving && d.servicesResolved) resolved();
}

void BleLink::deviceRemoved() {
  if (step_ == Step::Up)
    lost(address_ + " vanished from BlueZ");
  else if (step_ != Step::Idle)
    fail(address_ + " vanished from BlueZ");
}

void BleLink::resolved() {
  bluez_.loop().cancel(stepTimer_);
  step_ = Step::Subscribing;
  readChar_.clear();
  writeChar_.clear();
  for (const auto* c : bluez_.characteristicsOf(devicePath_)) {
    if (c->uuid == anki::kReadCharUuid) readChar_ = c->path;
    if (c->uuid == anki::kWriteCharUuid) writeChar_ = c->path;
  }
  if (readChar_.empty() || writeChar_.empty())
    return fail(address_ + " has no Anki " + (readChar_.empty() ? "read" : "write") +
                " characteristic: is it an Anki car?");
  subscribe();
}

void BleLink::acquire(const std::string& path, const char* method,
                      std::function<void(const sdbus::Error*, int fd)> then) {
  auto attempt = attempt_;
  std::weak_ptr<bool> alive = alive_;
  bluez_.proxy(path)
      .callMethodAsync(method)
      .onInterface(kCharIface)
      .withTimeout(timeouts_.subscribe)
      .withArguments(std::map<std::string, sdbus::Variant>{})
      .uponReplyInvoke([this, alive, attempt, method, then](
                           const sdbus::Error* error, sdbus::UnixFd fd, std::uint16_t /*mtu*/) {
        if (alive.expired() || !current(attempt)) return;
        if (error)
          log::debug(address(), std::string(method) + " refused (" + error->getName() + ")");
        then(error, error ? -1 : fd.release());
      });
  bluez_.pump().kick();
}

void BleLink::subscribe() {
  armStepTimer(timeouts_.subscribe, "enabling notifications on " + address_);
  acquire(readChar_, "AcquireNotify", [this](const sdbus::Error* error, int fd) {
    if (!error) {
      notifyFd_.assign(fd);
      waitNotify();
      return acquireWrite();
    }
    auto attempt = attempt_;
    std::weak_ptr<bool> alive = alive_;
    bluez_.proxy(readChar_)
        .callMethodAsync("StartNotify")
        .onInterface(kCharIface)
        .withTimeout(timeouts_.subscribe)
        .uponReplyInvoke([this, alive, attempt](const sdbus::Error* error) {
          if (alive.expired() || !current(attempt)) return;
          if (error) return fail(describe(*error, "enabling notifications on " + address_));
          acquireWrite();
        });
  });
}

void BleLink::acquireWrite() {
  acquire(writeChar_, "AcquireWrite", [this](const sdbus::Error* error, int fd) {
    if (!error) writeFd_.assign(fd);
    up();
  });
}

void BleLink::up() {
  bluez_.loop().cancel(stepTimer_);
  step_ = Step::Up;
  log::debug(address(), std::string("up; notifications by ") +
                            (notifyAcquired() ? "socket" : "signal") + ", writes by " +
                            (writeAcquired() ? "socket" : "call"));
  auto done = std::move(done_);
  done_ = nullptr;
  deliverState(true, "connected");
  if (done) done(std::nullopt);
}

void BleLink::closeChannels() {
  boost::system::error_code ec;
  if (notifyFd_.is_open()) notifyFd_.close(ec);
  if (writeFd_.is_open()) writeFd_.close(ec);
}

void BleLink::fail(const std::string& reason) {
  bool reachedDevice = step_ != Step::Connecting;
  abandonedConnect_ = !reachedDevice;
  ++attempt_;  // replies still on their way belong to a finished attempt
  bluez_.loop().cancel(stepTimer_);
  closeChannels();
  step_ = Step::Idle;
  // Half-connected: leave BlueZ clean for the next attempt.
  if (reachedDevice) {
    const Device* d = bluez_.device(devicePath_);
    if (d && d->connected) disconnectQuietly();
  }
  auto done = std::move(done_);
  done_ = nullptr;
  if (done) done(reason);
}

void BleLink::disconnectQuietly() {
  bluez_.proxy(devicePath_)
      .callMethodAsync("Disconnect")
      .onInterface(kDeviceIface)
      .withTimeout(timeouts_.disconnect)
      .uponReplyInvoke([](const sdbus::Error*) {});
  bluez_.pump().kick();
}

void BleLink::lost(const std::string& reason) {
  ++attempt_;
  closeChannels();
  step_ = Step::Idle;
  bool requested = disconnectRequested_;
  deliverState(false, requested ? "disconnected by the controller" : reason);
  if (!requested && onDropped) onDropped(reason);
}

void BleLink::waitNotify() {
  std::weak_ptr<bool> alive = alive_;
  auto attempt = attempt_;
  notifyFd_.async_wait(
      boost::asio::posix::stream_descriptor::wait_read,
      [this, alive, attempt](const boost::system::error_code& ec) {
        if (alive.expired() || !current(attempt) || ec == boost::asio::error::operation_aborted)
          return;
        if (ec) return lost("the notification socket of " + address_ + " failed: " + ec.message());
        std::uint8_t buf[512];  // one datagram is one notification
        for (;;) {
          ssize_t n = ::recv(notifyFd_.native_handle(), buf, sizeof buf, MSG_DONTWAIT);
          if (n > 0) {
            if (step_ == Step::Up) deliverFrame(std::span<const std::uint8_t>(buf, std::size_t(n)));
            if (alive.expired() || !current(attempt)) return;
            continue;
          }
          if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
          if (n < 0 && errno == EINTR) continue;
          // End of file: BlueZ closed the socket, the car is gone.
          if (step_ == Step::Up)
            lost(address_ + " disconnected (notification socket closed)");
          else
            fail(address_ + " closed its notification socket during setup");
          return;
        }
        waitNotify();
      });
}

void BleLink::value(const std::vector<std::uint8_t>& frame) {
  if (step_ == Step::Up) deliverFrame(frame);
}

bool BleLink::send(std::span<const std::uint8_t> frame) {
  if (step_ != Step::Up) return false;
  if (writeFd_.is_open()) {
    ssize_t n =
        ::send(writeFd_.native_handle(), frame.data(), frame.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n == static_cast<ssize_t>(frame.size())) return true;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) {
      log::debug(address(), std::string("write socket failed (") + std::strerror(errno) +
                                "): writes through WriteValue");
      boost::system::error_code ec;
      writeFd_.close(ec);
    }
  }
  writeValue(frame);
  return true;
}

void BleLink::writeValue(std::span<const std::uint8_t> frame) {
  std::weak_ptr<bool> alive = alive_;
  std::map<std::string, sdbus::Variant> options;
  options["type"] = sdbus::Variant(std::string("command"));  // write without response
  bluez_.proxy(writeChar_)
      .callMethodAsync("WriteValue")
      .onInterface(kCharIface)
      .withTimeout(timeouts_.subscribe)
      .withArguments(std::vector<std::uint8_t>(frame.begin(), frame.end()), options)
      .uponReplyInvoke([this, alive](const sdbus::Error* error) {
        if (alive.expired() || !error) return;
        log::warn(address(), describe(*error, "writing a frame"));
      });
  bluez_.pump().kick();
}

void BleLink::disconnect(std::function<void()> done) {
  disconnectRequested_ = true;
  if (step_ == Step::Idle) {
    if (done) done();
    return;
  }
  std::weak_ptr<bool> alive = alive_;
  auto finished = std::make_shared<bool>(false);
  auto finish = [this, alive, finished, done] {
    if (*finished) return;
    *finished = true;
    if (!alive.expired() && step_ == Step::Up) lost("disconnected by the controller");
    if (!alive.expired() && step_ != Step::Idle) fail("disconnected by the controller");
    if (done) done();
  };
  bluez_.proxy(devicePath_)
      .callMethodAsync("Disconnect")
      .onInterface(kDeviceIface)
      .withTimeout(timeouts_.disconnect)
      .uponReplyInvoke([finish](const sdbus::Error*) { finish(); });
  bluez_.pump().kick();
}

}  // namespace pitwall::ble
