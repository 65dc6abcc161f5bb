// A GATT link (gatt_link.hpp): finding, connecting, subscribing, and values as frames.
#include "engine/transport/gatt_link.hpp"

#include <sdbus-c++/sdbus-c++.h>

#include <algorithm>
#include <cctype>

#include "engine/core/log.hpp"
#include "engine/core/numbers.hpp"
#include "engine/transport/emergency_write.hpp"

namespace pitwall {

namespace {

std::optional<std::string> normalizeAddress(const std::string& text) {
  std::string out = text;
  if (out.size() != 17) return std::nullopt;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (i % 3 == 2) {
      if (out[i] != ':') return std::nullopt;
    } else if (!std::isxdigit(static_cast<unsigned char>(out[i]))) {
      return std::nullopt;
    }
    out[i] = static_cast<char>(std::toupper(static_cast<unsigned char>(out[i])));
  }
  return out;
}

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

std::string secondsText(Duration d) {
  return formatNumber(toSeconds(d)) + " s";
}

}  // namespace

GattLink::GattLink(Loop& loop, std::string address, GattProfile profile, GattLinkOptions options)
    : loop_(loop),
      address_(std::move(address)),
      profile_(std::move(profile)),
      options_(std::move(options)),
      bluez_(std::make_unique<ble::Bluez>(loop)),
      paths_(profile_.characteristics.size()),
      sockets_(profile_.characteristics.size()),
      alive_(std::make_shared<bool>(true)) {
  bluez_->onDevice = [this](const ble::Device& d) {
    if (gatt_ && d.path == gatt_->devicePath()) gatt_->deviceChanged(d);
    if (!scanning_.empty() && upper(d.address) == address_ && d.adapter == scanning_) {
      stopScan();
      connect(d.path);
    }
  };
  bluez_->onDeviceRemoved = [this](const std::string& path) {
    if (gatt_ && path == gatt_->devicePath() && !gatt_->idle()) gatt_->deviceRemoved();
  };
  bluez_->onValue = [this](const std::string& charPath, const std::vector<std::uint8_t>& v) {
    if (!gatt_ || !gatt_->up()) return;
    for (std::size_t i = 0; i < paths_.size(); ++i)
      if (sockets_[i] && paths_[i] == charPath && !sockets_[i]->isOpen()) return notified(i, v);
  };
  bluez_->onBluezBack = [this] {
    if (closed_ || (gatt_ && !gatt_->idle()) || !scanning_.empty()) return;
    loop_.cancel(retry_);
    retry_ = 0;
    findDevice();
  };
  for (std::size_t i = 0; i < sockets_.size(); ++i)
    if (profile_.characteristics[i].notify)
      sockets_[i] = std::make_unique<ble::NotifySocket>(loop.io());
  std::weak_ptr<bool> alive = alive_;
  loop_.post([this, alive] {
    if (!alive.expired()) start();
  });
}

GattLink::~GattLink() {
  *alive_ = false;
  emergency::removeStopper(std::exchange(emergencyStopper_, 0));
  loop_.cancel(retry_);
  loop_.cancel(scanTimer_);
  closeSockets();
  // Hang up rather than leave the device taken: BlueZ keeps an LE link after its client left.
  // The call is queued now and flushed when the bus connection closes (nobody waits for it).
  if (gatt_ && !gatt_->idle()) gatt_->disconnect(nullptr);
  if (!scanning_.empty()) bluez_->stopDiscovery(scanning_);
  gatt_.reset();
}

bool GattLink::connected() const {
  return gatt_ && gatt_->up();
}

std::string GattLink::refusal() const {
  if (connected()) return lastError_;
  if (closed_) return address() + ": closed";
  return address() + ": not connected" + (lastError_.empty() ? "" : " (" + lastError_ + ")");
}

bool GattLink::notifyAcquired() const {
  return std::all_of(sockets_.begin(), sockets_.end(),
                     [](const auto& s) { return !s || s->isOpen(); });
}

// ---- finding and connecting ----

void GattLink::start() {
  if (closed_) return;
  std::weak_ptr<bool> alive = alive_;
  bluez_->start([this, alive](std::optional<std::string> error) {
    if (alive.expired() || closed_) return;
    if (error) return retryLater(*error);
    findDevice();
  });
}

void GattLink::findDevice() {
  if (closed_) return;
  const ble::Adapter* wanted = nullptr;
  try {
    auto adapters =
        bluez_->pickAdapters(options_.adapter.empty() ? std::vector<std::string>{}
                                                      : std::vector<std::string>{options_.adapter});
    wanted = adapters.front();
  } catch (const ble::BleError& e) {
    return retryLater(e.what());
  }
  for (const auto& [path, d] : bluez_->devices())
    if (upper(d.address) == address_ && d.adapter == wanted->path) return connect(path);
  // BlueZ does not know it: look for it.
  scanning_ = wanted->path;
  log::info(address(), "looking for the " + profile_.name + " on " + wanted->name + " for up to " +
                           secondsText(options_.scan));
  std::weak_ptr<bool> alive = alive_;
  scanTimer_ = loop_.after(options_.scan, [this] {
    scanTimer_ = 0;
    scanTimedOut();
  });
  bluez_->startDiscovery(wanted->path,
                         [this, alive](std::optional<std::string> error) {
                           if (alive.expired() || !error || scanning_.empty()) return;
                           stopScan();
                           retryLater(*error);
                         },
                         {});
}

void GattLink::scanTimedOut() {
  std::string adapter = scanning_.substr(scanning_.rfind('/') + 1);
  stopScan();
  retryLater("no " + profile_.name + " with the address " + address_ + " found on " + adapter +
             " in " + secondsText(options_.scan) +
             ": is it switched on, in range, and not connected to another host?");
}

void GattLink::stopScan() {
  if (scanning_.empty()) return;
  loop_.cancel(scanTimer_);
  scanTimer_ = 0;
  bluez_->stopDiscovery(scanning_);
  scanning_.clear();
}

void GattLink::connect(const std::string& devicePath) {
  if (closed_) return;
  if (!gatt_) {
    gatt_ = std::make_unique<ble::GattClient>(*bluez_, devicePath, address_, options_.timeouts);
    gatt_->onResolved = [this] { resolved(); };
    gatt_->onClosed = [this] { closeSockets(); };
    gatt_->onState = [this](bool up, const std::string& reason) {
      if (up) {
        failures_ = 0;
        lastError_.clear();
        reportedDown_ = false;
        log::info(address(), "connected");
        registerEmergency(true);
        deliverState(true, "connected");
      } else {
        reportDown(reason);
      }
    };
    gatt_->onDropped = [this](const std::string& reason) { retryLater(reason); };
  } else {
    gatt_->retarget(devicePath);
  }
  ++attempts_;
  std::weak_ptr<bool> alive = alive_;
  gatt_->connect([this, alive](std::optional<std::string> error) {
    if (alive.expired() || !error) return;
    retryLater(*error);
  });
}

void GattLink::resolved() {
  for (auto& p : paths_) p.clear();
  for (const auto* c : bluez_->characteristicsOf(gatt_->devicePath()))
    for (std::size_t i = 0; i < paths_.size(); ++i)
      if (upper(c->uuid) == upper(profile_.characteristics[i].uuid)) paths_[i] = c->path;
  std::string missing;
  for (std::size_t i = 0; i < paths_.size(); ++i)
    if (paths_[i].empty())
      missing += (missing.empty() ? "" : ", ") + profile_.characteristics[i].name;
  if (!missing.empty())
    return gatt_->fail(address_ + " has no " + profile_.name + " characteristic " + missing +
                       ": is it an " + profile_.name + "?");
  gatt_->armStepTimer(options_.timeouts.subscribe, "enabling notifications on " + address_);
  subscribe(0);
}

// Notifications one characteristic after the other: a socket where BlueZ gives one, else
// StartNotify (values then come as PropertiesChanged through Bluez::onValue).
void GattLink::subscribe(std::size_t next) {
  while (next < sockets_.size() && !sockets_[next]) ++next;
  if (next == sockets_.size()) {
    log::debug(address(), std::string("up; notifications by ") +
                              (notifyAcquired() ? "socket" : "signal") + ", writes by call");
    return gatt_->ready();
  }
  const std::string& name = profile_.characteristics[next].name;
  gatt_->acquire(
      paths_[next], "AcquireNotify", [this, next, name](const sdbus::Error* error, int fd) {
        if (!error) {
          sockets_[next]->open(
              fd, [this, next](std::span<const std::uint8_t> bytes) { notified(next, bytes); },
              [this, name](const std::string&) {
                std::string what = name + " notification socket closed";
                if (gatt_->up())
                  gatt_->lost(address_ + " disconnected (" + what + ")");
                else
                  gatt_->fail(address_ + ": " + what + " during setup");
              });
          return subscribe(next + 1);
        }
        gatt_->startNotify(paths_[next], [this, next, name](const sdbus::Error* e) {
          if (e)
            return gatt_->fail(
                ble::describe(*e, "enabling notifications of " + name + " on " + address_));
          subscribe(next + 1);
        });
      });
}

void GattLink::closeSockets() {
  for (auto& s : sockets_)
    if (s) s->close();
}

void GattLink::reportDown(const std::string& why) {
  registerEmergency(false);
  lastError_ = why;
  // Once per outage: the first failed attempt, or the loss of a link that was up.
  if (reportedDown_) return;
  reportedDown_ = true;
  deliverState(false, why);
}

void GattLink::retryLater(const std::string& why) {
  std::weak_ptr<bool> alive = alive_;
  reportDown(why);
  if (alive.expired() || closed_) return;
  auto delay = options_.backoffMin;
  for (int i = 0; i < failures_ && delay < options_.backoffMax; ++i) delay *= 2;
  delay = std::min(delay, options_.backoffMax);
  ++failures_;
  log::warn(address(), why + "; trying again in " + secondsText(delay));
  loop_.cancel(retry_);
  retry_ = loop_.after(delay, [this] {
    retry_ = 0;
    if (gatt_ && !gatt_->idle()) return;
    findDevice();
  });
}

void GattLink::disconnect() {
  if (closed_) return;
  closed_ = true;
  loop_.cancel(retry_);
  retry_ = 0;
  stopScan();
  if (gatt_ && !gatt_->idle()) {
    gatt_->disconnect(nullptr);  // reports down: "disconnected by the controller"
  } else if (!reportedDown_) {
    reportDown("closed");
  }
}

void GattLink::reconnect(const std::string& reason) {
  if (closed_ || !gatt_ || gatt_->idle()) return;
  reportDown(reason);  // first: the hang-up's own "disconnected by the controller" is no news
  std::weak_ptr<bool> alive = alive_;
  gatt_->disconnect([this, alive, reason] {
    if (!alive.expired()) retryLater(reason);
  });
}

// ---- the stop outside the loop ----

void GattLink::setEmergencyStop(std::span<const std::uint8_t> frame) {
  emergencyStop_.assign(frame.begin(), frame.end());
  registerEmergency(connected());
}

void GattLink::registerEmergency(bool up) {
  emergency::removeStopper(std::exchange(emergencyStopper_, 0));
  if (!up || emergencyStop_.size() < 2 || emergencyStop_[0] >= paths_.size()) return;
  emergencyStopper_ = emergency::addStopper(ble::writeValueStopper(
      paths_[emergencyStop_[0]], {emergencyStop_.begin() + 1, emergencyStop_.end()}, true));
}

// ---- frames ----

void GattLink::notified(std::size_t index, std::span<const std::uint8_t> bytes) {
  if (!gatt_ || !gatt_->up()) return;
  deliverFrame(gatt::write(static_cast<std::uint8_t>(index), bytes));
}

bool GattLink::send(std::span<const std::uint8_t> frame) {
  if (!connected() || frame.empty() || frame[0] >= paths_.size()) return false;
  const std::size_t index = frame[0];
  if (frame.size() == 1)
    read(index);
  else
    write(index, {frame.begin() + 1, frame.end()});
  return true;
}

void GattLink::write(std::size_t index, std::vector<std::uint8_t> value) {
  std::weak_ptr<bool> alive = alive_;
  auto attempt = gatt_->attempt();
  std::string name = profile_.characteristics[index].name;
  std::map<std::string, sdbus::Variant> options;
  options["type"] = sdbus::Variant(std::string("request"));  // the device acknowledges
  bluez_->proxy(paths_[index])
      .callMethodAsync("WriteValue")
      .onInterface(ble::kCharIface)
      .withTimeout(options_.timeouts.subscribe)
      .withArguments(value, options)
      .uponReplyInvoke([this, alive, attempt, name](const sdbus::Error* error) {
        if (alive.expired() || !gatt_->current(attempt) || !error) return;
        lastError_ = ble::describe(*error, "writing " + name + " on " + address_);
        log::warn(address(), lastError_);
      });
  bluez_->pump().kick();
}

void GattLink::read(std::size_t index) {
  std::weak_ptr<bool> alive = alive_;
  auto attempt = gatt_->attempt();
  std::string name = profile_.characteristics[index].name;
  bluez_->proxy(paths_[index])
      .callMethodAsync("ReadValue")
      .onInterface(ble::kCharIface)
      .withTimeout(options_.timeouts.subscribe)
      .withArguments(std::map<std::string, sdbus::Variant>{})
      .uponReplyInvoke([this, alive, attempt, name, index](const sdbus::Error* error,
                                                           std::vector<std::uint8_t> value) {
        if (alive.expired() || !gatt_->current(attempt)) return;
        if (error) {
          lastError_ = ble::describe(*error, "reading " + name + " on " + address_);
          return log::warn(address(), lastError_);
        }
        auto frame = gatt::write(static_cast<std::uint8_t>(index | gatt::kReadAnswer), value);
        deliverFrame(frame);
      });
  bluez_->pump().kick();
}

// ---- making one ----

std::unique_ptr<GattLink> makeGattLink(Loop& loop, const std::string& address, GattProfile profile,
                                       GattLinkOptions options, std::string& error) {
  auto normalized = normalizeAddress(address);
  if (!normalized) {
    error = "'" + address + "' is not a Bluetooth address: write it as AA:BB:CC:DD:EE:FF";
    return nullptr;
  }
  try {
    return std::make_unique<GattLink>(loop, *normalized, std::move(profile), std::move(options));
  } catch (const ble::BleError& e) {
    error = e.what();
  } catch (const sdbus::Error& e) {
    error = "cannot reach the system D-Bus, which BlueZ is on (" + e.getMessage() + ")";
  }
  return nullptr;
}

}  // namespace pitwall
