#include "engine/vehicles/alphabot_ble_link.hpp"

#include <sdbus-c++/sdbus-c++.h>

#include <algorithm>
#include <cctype>
#include <sstream>

#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/core/overload.hpp"

namespace pitwall::alphabot {

namespace bt = ::pitwall::ble;  // the BlueZ client (ble:: here is the Alphabot codec)

namespace {

using ble::Characteristic;

// The characteristics the robot notifies, subscribed in this order.
constexpr std::array<Characteristic, 5> kNotified{
    Characteristic::Sensor, Characteristic::Toggle, Characteristic::Obstacle,
    Characteristic::PingClient, Characteristic::Calibrate};

std::size_t slot(Characteristic c) {
  return static_cast<std::size_t>(c);
}

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
  std::ostringstream s;
  s << toSeconds(d) << " s";
  return s.str();
}

}  // namespace

AlphabotBleLink::AlphabotBleLink(Loop& loop, std::string address, BleLinkOptions options)
    : loop_(loop),
      address_(std::move(address)),
      options_(std::move(options)),
      bluez_(std::make_unique<bt::Bluez>(loop)),
      alive_(std::make_shared<bool>(true)) {
  bluez_->onDevice = [this](const bt::Device& d) {
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
    for (auto c : kNotified)
      if (pathOf(c) == charPath && !sockets_[slot(c)]->isOpen()) return notified(c, v);
  };
  bluez_->onBluezBack = [this] {
    if (closed_ || (gatt_ && !gatt_->idle()) || !scanning_.empty()) return;
    loop_.cancel(retry_);
    retry_ = 0;
    findDevice();
  };
  for (auto c : kNotified) sockets_[slot(c)] = std::make_unique<bt::NotifySocket>(loop.io());
  std::weak_ptr<bool> alive = alive_;
  loop_.post([this, alive] {
    if (!alive.expired()) start();
  });
}

AlphabotBleLink::~AlphabotBleLink() {
  *alive_ = false;
  loop_.cancel(retry_);
  loop_.cancel(scanTimer_);
  closeSockets();
  // Hang up rather than leave the robot taken: BlueZ keeps an LE link after its client left. The
  // call is queued now and flushed when the bus connection closes (nobody waits for the reply).
  if (gatt_ && !gatt_->idle()) gatt_->disconnect(nullptr);
  if (!scanning_.empty()) bluez_->stopDiscovery(scanning_);
  gatt_.reset();
}

bool AlphabotBleLink::connected() const {
  return gatt_ && gatt_->up();
}

bool AlphabotBleLink::notifyAcquired() const {
  return std::all_of(kNotified.begin(), kNotified.end(),
                     [this](Characteristic c) { return sockets_[slot(c)]->isOpen(); });
}

// ---- finding and connecting ----

void AlphabotBleLink::start() {
  if (closed_) return;
  std::weak_ptr<bool> alive = alive_;
  bluez_->start([this, alive](std::optional<std::string> error) {
    if (alive.expired() || closed_) return;
    if (error) return retryLater(*error);
    findDevice();
  });
}

void AlphabotBleLink::findDevice() {
  if (closed_) return;
  const bt::Adapter* wanted = nullptr;
  try {
    auto adapters =
        bluez_->pickAdapters(options_.adapter.empty() ? std::vector<std::string>{}
                                                      : std::vector<std::string>{options_.adapter});
    wanted = adapters.front();
  } catch (const bt::BleError& e) {
    return retryLater(e.what());
  }
  for (const auto& [path, d] : bluez_->devices())
    if (upper(d.address) == address_ && d.adapter == wanted->path) return connect(path);
  // BlueZ does not know it: look for it.
  scanning_ = wanted->path;
  log::info(address(), "looking for the Alphabot on " + wanted->name + " for up to " +
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

void AlphabotBleLink::scanTimedOut() {
  std::string adapter = scanning_.substr(scanning_.rfind('/') + 1);
  stopScan();
  retryLater("no Alphabot with the address " + address_ + " found on " + adapter + " in " +
             secondsText(options_.scan) +
             ": is it switched on, in range, and not connected to another host?");
}

void AlphabotBleLink::stopScan() {
  if (scanning_.empty()) return;
  loop_.cancel(scanTimer_);
  scanTimer_ = 0;
  bluez_->stopDiscovery(scanning_);
  scanning_.clear();
}

void AlphabotBleLink::connect(const std::string& devicePath) {
  if (closed_) return;
  if (!gatt_) {
    gatt_ = std::make_unique<bt::GattClient>(*bluez_, devicePath, address_, options_.timeouts);
    gatt_->onResolved = [this] { resolved(); };
    gatt_->onClosed = [this] { closeSockets(); };
    gatt_->onState = [this](bool up, const std::string& reason) {
      if (up) {
        failures_ = 0;
        lastError_.clear();
        reportedDown_ = false;
        reportedUp_ = true;
        log::info(address(), "connected");
        if (onState) onState(true, "connected");
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

void AlphabotBleLink::resolved() {
  for (auto& p : paths_) p.clear();
  for (const auto* c : bluez_->characteristicsOf(gatt_->devicePath()))
    if (auto which = ble::characteristicByUuid(c->uuid)) paths_[slot(*which)] = c->path;
  std::string missing;
  for (const auto& i : ble::characteristics())
    if (pathOf(i.id).empty()) missing += (missing.empty() ? "" : ", ") + std::string(i.name);
  if (!missing.empty())
    return gatt_->fail(address_ + " has no Alphabot characteristic " + missing +
                       ": is it an Alphabot?");
  gatt_->armStepTimer(options_.timeouts.subscribe, "enabling notifications on " + address_);
  subscribe(0);
}

// Notifications one characteristic after the other: a socket where BlueZ gives one, else
// StartNotify (values then come as PropertiesChanged through Bluez::onValue).
void AlphabotBleLink::subscribe(std::size_t next) {
  if (next == kNotified.size()) {
    log::debug(address(), std::string("up; notifications by ") +
                              (notifyAcquired() ? "socket" : "signal") + ", writes by call");
    return gatt_->ready();
  }
  Characteristic c = kNotified[next];
  gatt_->acquire(pathOf(c), "AcquireNotify", [this, c, next](const sdbus::Error* error, int fd) {
    if (!error) {
      sockets_[slot(c)]->open(
          fd, [this, c](std::span<const std::uint8_t> bytes) { notified(c, bytes); },
          [this, c](const std::string&) {
            std::string what = std::string(ble::info(c).name) + " notification socket closed";
            if (gatt_->up())
              gatt_->lost(address_ + " disconnected (" + what + ")");
            else
              gatt_->fail(address_ + ": " + what + " during setup");
          });
      return subscribe(next + 1);
    }
    gatt_->startNotify(pathOf(c), [this, c, next](const sdbus::Error* error) {
      if (error)
        return gatt_->fail(bt::describe(*error, std::string("enabling notifications of ") +
                                                    ble::info(c).name + " on " + address_));
      subscribe(next + 1);
    });
  });
}

void AlphabotBleLink::closeSockets() {
  for (auto& s : sockets_)
    if (s) s->close();
}

void AlphabotBleLink::reportDown(const std::string& why) {
  lastError_ = why;
  // Once per outage: the first failed attempt, or the loss of a link that was up.
  if (reportedDown_) return;
  reportedDown_ = true;
  reportedUp_ = false;
  if (onState) onState(false, why);
}

void AlphabotBleLink::retryLater(const std::string& why) {
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

void AlphabotBleLink::close() {
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

// ---- frames ----

void AlphabotBleLink::notified(Characteristic c, std::span<const std::uint8_t> bytes) {
  if (!gatt_ || !gatt_->up()) return;
  auto message = ble::decodeResponse(c, bytes);
  if (!message) {
    log::warn(address(), message.error().message + " [" + toHex(bytes) + "]");
    if (onMalformed) onMalformed(message.error().message + " [" + toHex(bytes) + "]");
    return;
  }
  std::visit(Overload{
                 [this](const Response& r) {
                   if (onResponse) onResponse(r);
                 },
                 [this](const ble::TogglesReport& t) { toggles_ = t.toggles; },
                 [this](const ble::Heartbeat&) { ++heartbeats_; },
                 [](const ble::PathPending&) {},
             },
             *message);
}

bool AlphabotBleLink::send(const Request& request) {
  if (!connected()) {
    lastError_ = "the Alphabot at " + address_ + " is not connected; nothing sent";
    return false;
  }
  if (const auto* ping = std::get_if<Ping>(&request)) {
    // Over BLE a ping is a read of PINGCLIENT: the robot's reply is the answer.
    std::int64_t time = ping->time;
    read(Characteristic::PingClient, [this, time](std::vector<std::uint8_t>) {
      if (onResponse) onResponse(PingReply{time});
    });
    return true;
  }
  auto value = ble::encode(request);
  if (!value) {
    lastError_ = value.error().message;
    return false;
  }
  write(*value, std::holds_alternative<NavigateTo>(request));
  return true;
}

bool AlphabotBleLink::query(ble::SensorKind kind) {
  if (!connected()) {
    lastError_ = "the Alphabot at " + address_ + " is not connected; nothing sent";
    return false;
  }
  auto value = ble::encode(ble::SensorQuery{kind});
  if (!value) {
    lastError_ = value.error().message;
    return false;
  }
  write(*value, false);
  return true;
}

void AlphabotBleLink::write(const ble::BleValue& value, bool thenReadPath) {
  std::weak_ptr<bool> alive = alive_;
  auto attempt = gatt_->attempt();
  const char* name = ble::info(value.characteristic).name;
  std::map<std::string, sdbus::Variant> options;
  options["type"] = sdbus::Variant(std::string("request"));  // the robot acknowledges
  bluez_->proxy(pathOf(value.characteristic))
      .callMethodAsync("WriteValue")
      .onInterface(bt::kCharIface)
      .withTimeout(options_.timeouts.subscribe)
      .withArguments(value.bytes, options)
      .uponReplyInvoke([this, alive, attempt, name, thenReadPath](const sdbus::Error* error) {
        if (alive.expired() || !gatt_->current(attempt)) return;
        if (error) {
          lastError_ = bt::describe(*error, std::string("writing ") + name + " on " + address_);
          return log::warn(address(), lastError_);
        }
        if (thenReadPath) readPath(loop_.now() + options_.pathTimeout);
      });
  bluez_->pump().kick();
}

void AlphabotBleLink::read(Characteristic c, std::function<void(std::vector<std::uint8_t>)> then) {
  std::weak_ptr<bool> alive = alive_;
  auto attempt = gatt_->attempt();
  const char* name = ble::info(c).name;
  bluez_->proxy(pathOf(c))
      .callMethodAsync("ReadValue")
      .onInterface(bt::kCharIface)
      .withTimeout(options_.timeouts.subscribe)
      .withArguments(std::map<std::string, sdbus::Variant>{})
      .uponReplyInvoke([this, alive, attempt, name, then](const sdbus::Error* error,
                                                          std::vector<std::uint8_t> value) {
        if (alive.expired() || !gatt_->current(attempt)) return;
        if (error) {
          lastError_ = bt::describe(*error, std::string("reading ") + name + " on " + address_);
          return log::warn(address(), lastError_);
        }
        then(std::move(value));
      });
  bluez_->pump().kick();
}

void AlphabotBleLink::readPath(TimePoint deadline) {
  std::weak_ptr<bool> alive = alive_;
  read(Characteristic::PathFinding, [this, alive, deadline](std::vector<std::uint8_t> bytes) {
    auto message = ble::decodeResponse(Characteristic::PathFinding, bytes);
    if (!message) {
      if (onMalformed) onMalformed(message.error().message + " [" + toHex(bytes) + "]");
      return;
    }
    if (std::holds_alternative<ble::PathPending>(*message)) {
      if (loop_.now() >= deadline) {
        lastError_ = "PATH_FINDING on " + address_ + " still pending after " +
                     secondsText(options_.pathTimeout) + ": no path delivered";
        return log::warn(address(), lastError_);
      }
      auto attempt = gatt_->attempt();
      loop_.after(options_.pathPoll, [this, alive, attempt, deadline] {
        if (!alive.expired() && gatt_->current(attempt) && gatt_->up()) readPath(deadline);
      });
      return;
    }
    if (const auto* r = std::get_if<Response>(&*message))
      if (onResponse) onResponse(*r);
  });
}

// ---- making one ----

std::unique_ptr<RobotLink> makeBleRobotLink(Loop& loop, const std::string& address,
                                            std::string& error) {
  return makeBleRobotLink(loop, address, BleLinkOptions{}, error);
}

std::unique_ptr<RobotLink> makeBleRobotLink(Loop& loop, const std::string& address,
                                            BleLinkOptions options, std::string& error) {
  auto normalized = normalizeAddress(address);
  if (!normalized) {
    error = "'" + address + "' is not a Bluetooth address: write it as AA:BB:CC:DD:EE:FF";
    return nullptr;
  }
  try {
    return std::make_unique<AlphabotBleLink>(loop, *normalized, std::move(options));
  } catch (const bt::BleError& e) {
    error = e.what();
  } catch (const sdbus::Error& e) {
    error = "cannot reach the system D-Bus, which BlueZ is on (" + e.getMessage() + ")";
  }
  return nullptr;
}

}  // namespace pitwall::alphabot
