#pragma once
// The fake BlueZ's model, shared by its three parts: fake_bluez.cpp (adapters, discovery,
// devices, the public API), fake_gatt.cpp (GATT objects, notification and write channels, the
// link to the simulated car) and fake_faults.cpp (the faults it injects). Private to
// tests/fake_bluez.

#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>

#include <sdbus-c++/sdbus-c++.h>

#include "engine/core/log.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/sim/grid.hpp"
#include "engine/sim/track.hpp"
#include "engine/transport/bluez_api.hpp"
#include "tests/fake_bluez/fake_alphabot.hpp"
#include "tests/fake_bluez/fake_bluez.hpp"

namespace pitwall::testing::fake {

namespace api = ble::api;

using namespace std::chrono_literals;
using Dict = std::map<std::string, sdbus::Variant>;

constexpr const char* kComponent = "fake-bluez";

// Timings: a few BLE connection intervals; short, so that tests stay fast.
constexpr Duration kFirstSeen = 20ms;      // StartDiscovery → first advertisement of a car
constexpr Duration kSeenSpacing = 10ms;    // between the cars of one adapter
constexpr Duration kAdvertPeriod = 200ms;  // advertisements while discovering (RSSI updates)
constexpr Duration kConnectDelay = 30ms;   // Connect → link up (or, refused, the error)
constexpr Duration kResolveDelay = 50ms;   // link up → ServicesResolved
constexpr std::uint16_t kMtu = 23;         // ATT default: 20-byte values, as Anki frames
constexpr int kRssiThreshold = 8;          // device.c RSSI_THRESHOLD: smaller changes are not sent
constexpr std::int16_t kTxPower = 0;       // Anki cars advertise a TX power level (drive-sdk)

// BlueZ's errors (src/error.c).
inline sdbus::Error bluezError(const std::string& name, const std::string& text) {
  return sdbus::Error("org.bluez.Error." + name, text);
}
inline sdbus::Error notReady() {
  return bluezError("NotReady", "Resource Not Ready");
}
inline sdbus::Error busy() {
  return bluezError("InProgress", "Operation already in progress");
}
inline sdbus::Error inProgress() {
  return bluezError("InProgress", "In Progress");
}
inline sdbus::Error notSupported() {
  return bluezError("NotSupported", "Operation is not supported");
}
inline sdbus::Error invalidArgs() {
  return bluezError("InvalidArguments", "Invalid arguments in method call");
}
inline sdbus::Error doesNotExist() {
  return bluezError("DoesNotExist", "Does Not Exist");
}
inline sdbus::Error notConnected() {
  return bluezError("NotConnected", "Not Connected");
}
inline sdbus::Error notPermitted(const std::string& text) {
  return bluezError("NotPermitted", text);
}
inline sdbus::Error failed(const std::string& text) {
  return bluezError("Failed", text);
}
inline const char* const kConnectionAborted = "le-connection-abort-by-local";

// "e0:00:00:00:00:01" → "E0:00:00:00:00:01"; throws std::invalid_argument.
inline std::string normalizeAddress(std::string_view text) {
  std::string out(text);
  bool ok = out.size() == 17;
  for (std::size_t i = 0; ok && i < out.size(); ++i) {
    if (i % 3 == 2)
      ok = out[i] == ':';
    else
      ok = std::isxdigit(static_cast<unsigned char>(out[i])) != 0;
    out[i] = static_cast<char>(std::toupper(static_cast<unsigned char>(out[i])));
  }
  if (!ok)
    throw std::invalid_argument("'" + std::string(text) +
                                "' is not a Bluetooth address: write it as E0:00:00:00:00:01");
  return out;
}

inline std::string defaultAddress(int index) {
  char buf[18];
  std::snprintf(buf, sizeof buf, "E0:00:00:00:%02X:%02X", ((index + 1) >> 8) & 0xff,
                (index + 1) & 0xff);
  return buf;
}

// A UUID as BlueZ compares them: 128-bit, lower case (adapter.c parse_uuids). nullopt: invalid.
inline std::optional<std::string> uuid128(std::string_view text) {
  auto hex = [](std::string_view s) {
    return std::all_of(s.begin(), s.end(),
                       [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; });
  };
  std::string s(text);
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (s.size() == 4 && hex(s)) return "0000" + s + "-0000-1000-8000-00805f9b34fb";
  if (s.size() == 8 && hex(s)) return s + "-0000-1000-8000-00805f9b34fb";
  if (s.size() == 36 && s[8] == '-' && s[13] == '-' && s[18] == '-' && s[23] == '-') {
    std::string digits = s;
    digits.erase(std::remove(digits.begin(), digits.end(), '-'), digits.end());
    if (digits.size() == 32 && hex(digits)) return s;
  }
  return std::nullopt;
}

// SetDiscoveryFilter's dictionary (adapter.c parse_discovery_filter_dict).
struct DiscoveryFilter {
  std::vector<std::string> uuids;
  std::optional<std::int16_t> rssi;
  std::optional<std::uint16_t> pathloss;
  std::string transport = "auto";
  bool duplicateData = false;
  bool discoverable = false;
  std::string pattern;
};

// nullopt for an empty dictionary (which clears the filter); throws InvalidArguments.
inline std::optional<DiscoveryFilter> parseFilter(const Dict& dict) {
  if (dict.empty()) return std::nullopt;
  DiscoveryFilter f;
  for (const auto& [key, value] : dict) {
    if (key == "UUIDs" && value.containsValueOfType<std::vector<std::string>>()) {
      for (const auto& u : value.get<std::vector<std::string>>()) {
        auto full = uuid128(u);
        if (!full) throw invalidArgs();
        f.uuids.push_back(*full);
      }
    } else if (key == "RSSI" && value.containsValueOfType<std::int16_t>()) {
      f.rssi = value.get<std::int16_t>();
      if (*f.rssi > 20 || *f.rssi < -127) throw invalidArgs();
    } else if (key == "Pathloss" && value.containsValueOfType<std::uint16_t>()) {
      f.pathloss = value.get<std::uint16_t>();
      if (*f.pathloss > 137) throw invalidArgs();  // PATHLOSS_MAX
    } else if (key == "Transport" && value.containsValueOfType<std::string>()) {
      f.transport = value.get<std::string>();
      if (f.transport != "auto" && f.transport != "le" && f.transport != "bredr")
        throw invalidArgs();
    } else if (key == "DuplicateData" && value.containsValueOfType<bool>()) {
      f.duplicateData = value.get<bool>();
    } else if (key == "Discoverable" && value.containsValueOfType<bool>()) {
      f.discoverable = value.get<bool>();
    } else if (key == "Pattern" && value.containsValueOfType<std::string>()) {
      f.pattern = value.get<std::string>();
    } else {
      throw invalidArgs();  // unknown key, or a value of the wrong type
    }
  }
  if (f.rssi && f.pathloss) throw invalidArgs();  // only one of them, never both
  return f;
}

inline bool validUtf8(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    auto c = static_cast<unsigned char>(s[i]);
    int more = c < 0x80             ? 0
               : (c & 0xe0) == 0xc0 ? 1
               : (c & 0xf0) == 0xe0 ? 2
               : (c & 0xf8) == 0xf0 ? 3
                                    : -1;
    if (more < 0 || (more == 1 && c < 0xc2) || i + more >= s.size() + (more ? 0 : 1)) return false;
    for (int k = 1; k <= more; ++k)
      if ((static_cast<unsigned char>(s[i + k]) & 0xc0) != 0x80) return false;
    i += more + 1;
  }
  return true;
}

struct Io {
  Io(boost::asio::io_context& io, int fd) : fd(io, fd) {}
  boost::asio::posix::stream_descriptor fd;
  std::shared_ptr<int> token = std::make_shared<int>(0);  // expires when the Io goes away
};

inline void closeIo(std::unique_ptr<Io>& io) {
  if (!io) return;
  boost::system::error_code ec;
  io->fd.cancel(ec);
  io->fd.close(ec);
  io.reset();
}

struct Adapter;

struct Characteristic {
  std::string path;
  std::string uuid;
  std::vector<std::string> flags;
  bool notify = false;        // "notify"
  bool writeCommand = false;  // "write-without-response"
  bool writeRequest = false;  // "write"
  std::unique_ptr<sdbus::IObject> object;
  std::vector<std::uint8_t> value;
  std::set<std::string> notifySessions;  // senders that called StartNotify
  std::unique_ptr<Io> notifyIo;          // our end of AcquireNotify's socket
  std::unique_ptr<Io> writeIo;           // our end of AcquireWrite's socket
  bool writeWatched = false;             // a wait on writeIo is pending
};

struct Device {
  int index = 0;  // the car's index
  std::string address;
  std::string path;
  Adapter* adapter = nullptr;
  sim::SimCar* car = nullptr;
  std::int16_t baseRssi = -60;
  // BlueZ invalidates RSSI when discovery stops (device_set_rssi(dev, 0)), so the first sighting
  // of the next discovery always reports it. sdbus-c++ cannot invalidate a property: we mark it.
  bool rssiStale = false;

  // What BlueZ knows: the last advertisement, and what the client set.
  std::unique_ptr<sdbus::IObject> object;  // null while BlueZ does not know the device
  bool hasName = false;                    // the Name property was registered
  std::vector<std::uint8_t> manufacturer;  // 8 raw bytes
  std::vector<std::uint8_t> localName;     // raw bytes
  std::string name;                        // bluezName(localName)
  std::string alias;                       // set by a client; empty: none
  std::int16_t rssi = 0;
  bool trusted = false;
  bool blocked = false;

  // The link.
  bool connecting = false;
  bool connected = false;
  bool resolved = false;
  std::uint64_t generation = 0;  // one per connection: callbacks of older ones do nothing
  std::shared_ptr<sdbus::Result<>> pendingConnect;
  Loop::TimerId connectTimer = 0;
  Loop::TimerId resolveTimer = 0;
  std::unique_ptr<sdbus::IObject> service;
  std::unique_ptr<Characteristic> readChar;   // be15bee0: read, notify
  std::unique_ptr<Characteristic> writeChar;  // be15bee1: read, write-without-response, write
  // An Alphabot instead of a car (car is then null): the robot, and its eight characteristics
  // by alphabot::ble::Characteristic.
  std::unique_ptr<FakeAlphabot> robot;
  std::array<std::unique_ptr<Characteristic>, 8> robotChars;
  // Neither a car nor a robot: a device connected to the adapter by someone else (car and robot
  // are then null), known to BlueZ from the start (FakeBluezOptions::bystanders).
  bool bystander = false;

  // Faults.
  bool refused = false;
  bool vanished = false;
  std::optional<TimePoint> firstConnect;
  struct Scheduled {
    FakeBluez::Fault fault;
    Duration after, lasting;
  };
  std::vector<Scheduled> scheduled;
  bool muted = false;         // Mute: notifications are lost
  bool writesFail = false;    // WriteFail: writes fail
  bool writesHang = false;    // WriteHang: the write socket is not read
  bool connectHangs = false;  // ConnectHang: a connection attempt pends
  bool notifyHeld = false;    // NotifyHeld: bluetoothd's leftover notify request refuses all
  // NotifySlow: the next AcquireNotify is answered this late (zero: at once), and its answer
  // while it waits.
  Duration notifySlow{};
  std::shared_ptr<sdbus::Result<sdbus::UnixFd, std::uint16_t>> pendingNotify;
  Loop::TimerId notifyTimer = 0;

  FakeBluezCounters counters;

  std::string currentAlias() const {
    if (!alias.empty()) return alias;
    if (!name.empty()) return name;
    std::string a = address;
    std::replace(a.begin(), a.end(), ':', '-');
    return a;
  }
};

struct DiscoveryClient {
  std::optional<DiscoveryFilter> filter;
  bool discovering = false;  // else it only pre-set a filter
};

struct Adapter {
  int index = 0;
  std::string path;
  std::string address;
  std::string name;
  std::string alias;
  bool powered = true;
  bool plugged = true;  // false: unplugged (FakeBluez::unplug), its object off the bus
  bool discoverable = false;
  bool pairable = true;
  std::unique_ptr<sdbus::IObject> object;
  std::map<std::string, DiscoveryClient> clients;  // by unique bus name
  bool discovering = false;
  std::vector<Loop::TimerId> sightings;  // first advertisements after the start
  Loop::TimerId advertTimer = 0;

  bool anyDiscovering() const {
    return std::any_of(clients.begin(), clients.end(),
                       [](const auto& c) { return c.second.discovering; });
  }
};

}  // namespace pitwall::testing::fake

namespace pitwall::testing {

using namespace fake;

struct FakeBluez::State {
  State(Loop& loop, sdbus::IConnection& connection, Options options);
  ~State();

  Loop& loop;
  sdbus::IConnection& conn;
  Options options;
  DbusPump pump;
  std::shared_ptr<bool> alive = std::make_shared<bool>(true);
  std::mt19937_64 rng;
  std::unique_ptr<sim::World> world;
  std::unique_ptr<sdbus::IObject> root;
  std::vector<std::unique_ptr<Adapter>> adapters;
  std::vector<std::unique_ptr<Device>> devices;
  std::set<Loop::TimerId> timers;
  sdbus::Slot nameWatch;

  // Loop helpers: timers die with the fake; each callback ends with a kick of the pump.
  Loop::TimerId after(Duration delay, std::function<void()> fn);
  void cancel(Loop::TimerId& id);
  void later(std::function<void()> fn);

  Device& device(std::string_view address);
  const Device& device(std::string_view address) const;

  // Objects.
  void exportAdapter(Adapter& a);
  void exportDevice(Device& d);
  void unexportDevice(Device& d);
  void exportGatt(Device& d);
  void removeGatt(Device& d);
  void exportService(Device& d);
  void exportAlphabotGatt(Device& d);
  std::string serviceUuid(const Device& d) const;
  std::unique_ptr<Characteristic> makeCharacteristic(Device& d, const std::string& path,
                                                     std::string_view uuid,
                                                     std::vector<std::string> flags);
  void emit(sdbus::IObject* object, const char* iface, const std::vector<std::string>& props);

  // Discovery.
  void startDiscovery(Adapter& a, const std::string& sender);
  void stopDiscovery(Adapter& a, const std::string& sender);
  void startScan(Adapter& a);
  void stopScan(Adapter& a);
  void armAdvertTick(Adapter& a);
  void advertise(Device& d);
  bool wanted(const Adapter& a, const Device& d, std::int16_t rssi, const std::string& name) const;
  void clientGone(const std::string& uniqueName);

  // Links.
  void connect(Device& d, sdbus::Result<>&& result);
  void acquireNotify(Device& d, Characteristic& ch,
                     sdbus::Result<sdbus::UnixFd, std::uint16_t>&& result);
  void abandonNotify(Device& d);  // a Disconnect while AcquireNotify waits (NotifySlow)
  void finishConnect(Device& d);
  void failConnect(Device& d, const std::string& why);
  void linkUp(Device& d);
  void linkDown(Device& d, bool tellCar);
  void forget(Device& d);
  void toCar(Device& d, std::span<const std::uint8_t> frame);
  void toDevice(Device& d, Characteristic& ch, std::span<const std::uint8_t> frame);
  // A notification on `ch` (socket or PropertiesChanged); true: a D-Bus signal went out.
  bool notify(Device& d, Characteristic* ch, std::span<const std::uint8_t> frame);
  bool toClient(Device& d, std::span<const std::uint8_t>
                               frame);  // true: a D-Bus signal went out (the pump needs a kick)
  void watchNotifyIo(Device& d, Characteristic& ch);
  void watchWriteIo(Device& d, Characteristic& ch);
  void closeNotifyIo(Characteristic& ch);
  void closeWriteIo(Characteristic& ch);

  // Characteristic methods.
  std::vector<std::uint8_t> readValue(Device& d, Characteristic& ch, const Dict& options);
  void writeValue(Device& d, Characteristic& ch, const std::vector<std::uint8_t>& value,
                  const Dict& options);
  std::tuple<sdbus::UnixFd, std::uint16_t> acquire(Device& d, Characteristic& ch, bool write);
  void startNotify(Device& d, Characteristic& ch);
  void stopNotify(Characteristic& ch);

  // Faults.
  void drop(Device& d);
  void vanish(Device& d);
  bool inject(Device& d, std::span<const std::uint8_t> bytes);
  void arm(Device& d, const Device::Scheduled& fault);
  void unplug(Adapter& a);
  void plugBack(Adapter& a);
  void stopBluez();
  void startBluez();
  bool running = true;  // org.bluez is on the bus (FakeBluez::restart)
};

}  // namespace pitwall::testing
