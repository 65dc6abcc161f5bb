#include "engine/transport/ble_link.hpp"

#include <sys/socket.h>

#include <sdbus-c++/sdbus-c++.h>
#include <cerrno>
#include <cstring>

#include "engine/core/emergency_stops.hpp"
#include "engine/core/log.hpp"
#include "engine/transport/emergency_write.hpp"

namespace pitwall::ble {

BleLink::BleLink(Bluez& bluez, std::string devicePath, std::string address, LinkTimeouts timeouts)
    : gatt_(bluez, std::move(devicePath), std::move(address), timeouts),
      notify_(bluez.loop().io()),
      writeFd_(bluez.loop().io()),
      alive_(std::make_shared<bool>(true)) {
  gatt_.onResolved = [this] { resolved(); };
  gatt_.onClosed = [this] { closeChannels(); };
  gatt_.onState = [this](bool up, const std::string& reason) { deliverState(up, reason); };
  gatt_.onDropped = [this](const std::string& reason) {
    if (onDropped) onDropped(reason);
  };
}

BleLink::~BleLink() {
  *alive_ = false;
  closeChannels();
}

void BleLink::connect(Done done) {
  gatt_.connect(std::move(done));
}

void BleLink::resolved() {
  readChar_.clear();
  writeChar_.clear();
  for (const auto* c : gatt_.bluez().characteristicsOf(gatt_.devicePath())) {
    if (c->uuid == anki::kReadCharUuid) readChar_ = c->path;
    if (c->uuid == anki::kWriteCharUuid) writeChar_ = c->path;
  }
  if (readChar_.empty() || writeChar_.empty())
    return gatt_.fail(gatt_.address() + " has no Anki " + (readChar_.empty() ? "read" : "write") +
                      " characteristic: is it an Anki car?");
  subscribe();
}

void BleLink::subscribe() {
  const std::string& address = gatt_.address();
  gatt_.armStepTimer(gatt_.timeouts().subscribe, "enabling notifications on " + address);
  gatt_.acquire(readChar_, "AcquireNotify", [this](const sdbus::Error* error, int fd) {
    if (!error) {
      notify_.open(
          fd,
          [this](std::span<const std::uint8_t> frame) {
            if (gatt_.up()) deliverFrame(frame);
          },
          [this](const std::string&) {
            // BlueZ closed the socket: the car is gone.
            if (gatt_.up())
              gatt_.lost(gatt_.address() + " disconnected (notification socket closed)");
            else
              gatt_.fail(gatt_.address() + " closed its notification socket during setup");
          });
      return acquireWrite();
    }
    gatt_.startNotify(readChar_, [this](const sdbus::Error* error) {
      if (error)
        return gatt_.fail(describe(*error, "enabling notifications on " + gatt_.address()));
      acquireWrite();
    });
  });
}

void BleLink::acquireWrite() {
  gatt_.acquire(writeChar_, "AcquireWrite", [this](const sdbus::Error* error, int fd) {
    if (!error) {
      writeFd_.assign(fd);
      registerEmergency();
    }
    up();
  });
}

void BleLink::up() {
  log::debug(address(), std::string("up; notifications by ") +
                            (notifyAcquired() ? "socket" : "signal") + ", writes by " +
                            (writeAcquired() ? "socket" : "call"));
  gatt_.ready();
  registerEmergency();
}

void BleLink::closeChannels() {
  stalledSince_.reset();
  failing_ = 0;
  notify_.close();
  closeWrite();
  emergency::removeStopper(std::exchange(emergencyStopper_, 0));
}

void BleLink::closeWrite() {
  emergency::remove(std::exchange(emergencySlot_, -1));
  boost::system::error_code ec;
  if (writeFd_.is_open()) writeFd_.close(ec);
}

void BleLink::setEmergencyStop(std::span<const std::uint8_t> frame) {
  emergencyStop_.assign(frame.begin(), frame.end());
  emergency::remove(std::exchange(emergencySlot_, -1));
  emergency::removeStopper(std::exchange(emergencyStopper_, 0));
  registerEmergency();
}

void BleLink::registerEmergency() {
  if (emergencyStop_.empty()) return;
  if (writeFd_.is_open()) {
    emergency::removeStopper(std::exchange(emergencyStopper_, 0));
    if (emergencySlot_ < 0)
      emergencySlot_ = emergency::add(writeFd_.native_handle(), emergencyStop_);
  } else if (emergencyStopper_ == 0 && !writeChar_.empty() && gatt_.up()) {
    // writes go through WriteValue: so does the stop, on a connection of its own
    emergencyStopper_ = emergency::addStopper(writeValueStopper(writeChar_, emergencyStop_, false));
  }
}

void BleLink::value(const std::vector<std::uint8_t>& frame) {
  if (gatt_.up()) deliverFrame(frame);
}

void BleLink::reconnect(const std::string& reason) {
  if (!gatt_.up()) return;
  gatt_.drop(reason);
}

LinkHealth BleLink::health() const {
  LinkHealth h = health_;
  if (const Device* d = gatt_.bluez().device(gatt_.devicePath()))
    if (d->rssi) h.rssi = *d->rssi;
  return h;
}

std::string BleLink::refusal() const {
  return stalledSince_ ? "the car's link takes no writes (BlueZ reads none); it is dropped, "
                         "which stops the car, once that has lasted " +
                             std::to_string(static_cast<int>(kWriteStall * 1000)) + " ms"
                       : std::string();
}

bool BleLink::send(std::span<const std::uint8_t> frame) {
  if (!gatt_.up()) return false;
  if (writeFd_.is_open()) {
    ssize_t n =
        ::send(writeFd_.native_handle(), frame.data(), frame.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n == static_cast<ssize_t>(frame.size())) {
      stalledSince_.reset();
      return true;
    }
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      // The socket is full: BlueZ takes nothing from it (the controller is stuck, the link is
      // dying). A car whose commands cannot reach it cannot be stopped either, except by its
      // link going: after kWriteStall, the link is dropped (the car stops) and made again.
      const double now = gatt_.bluez().loop().seconds();
      if (!stalledSince_) stalledSince_ = now;
      if (now - *stalledSince_ >= kWriteStall) {
        stalledSince_.reset();
        ++health_.stalls;
        reconnect(gatt_.address() + " took no write for " +
                  std::to_string(static_cast<int>(kWriteStall * 1000)) +
                  " ms: its link is dropped, which stops the car, and made again");
      }
      return false;
    }
    if (n < 0) {
      log::debug(address(), std::string("write socket failed (") + std::strerror(errno) +
                                "): writes through WriteValue");
      closeWrite();
      registerEmergency();
    }
  }
  writeValue(frame);
  return true;
}

void BleLink::writeValue(std::span<const std::uint8_t> frame) {
  std::weak_ptr<bool> alive = alive_;
  std::map<std::string, sdbus::Variant> options;
  options["type"] = sdbus::Variant(std::string("command"));  // write without response
  gatt_.bluez()
      .proxy(writeChar_)
      .callMethodAsync("WriteValue")
      .onInterface(kCharIface)
      .withTimeout(gatt_.timeouts().subscribe)
      .withArguments(std::vector<std::uint8_t>(frame.begin(), frame.end()), options)
      .uponReplyInvoke([this, alive](const sdbus::Error* error) {
        if (alive.expired()) return;
        // One line when writes start failing, one when they go through again: not one a frame
        if (!error) {
          if (failing_ > 0)
            log::info(address(), "writes go through again (" + std::to_string(failing_) +
                                     " failed meanwhile)");
          failing_ = 0;
          return;
        }
        ++health_.writeFailures;
        if (failing_++ == 0) log::warn(address(), describe(*error, "writing a frame"));
      });
  gatt_.bluez().pump().kick();
}

}  // namespace pitwall::ble
