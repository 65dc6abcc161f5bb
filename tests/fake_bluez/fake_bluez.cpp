#include "tests/fake_bluez/fake_bluez.hpp"

// How the fake follows BlueZ 5.66 (src/adapter.c, src/device.c, src/gatt-client.c, src/eir.c,
// src/error.c), and where it does not:
// - Error names and texts are BlueZ's (error.c): StartDiscovery twice → InProgress "Operation
//   already in progress"; StopDiscovery without a start → Failed "No discovery started"; a
//   failed LE connection → Failed "le-connection-abort-by-local"; Connect on a connected device
//   succeeds at once (device.c dev_connect); Disconnect when not connected → NotConnected.
// - Name follows eir.c name2utf8 (see bluezName); no Name property when that gives "", and Alias
//   is then the address with dashes (device.c dev_property_get_alias).
// - Differences: GATT objects are removed on every disconnect (BlueZ does so only when its GATT
//   cache is off, Cache=no / Cache=yes for unpaired devices; the stock Cache=always keeps them,
//   and method calls on them then fail with Failed "Not connected"); there is no CCCD descriptor
//   object under the notify characteristic; Value exists before the first notification (empty);
//   RSSI and TxPower keep their last values after discovery stops (BlueZ invalidates them; the
//   fake then reports RSSI at the next discovery's first sighting, as BlueZ does);
//   devices stay known after discovery stops (BlueZ drops temporary ones after 30 s);
//   AdvertisingData carries the local name (0x09), which stock BlueZ does not export; method
//   replies come before the PropertiesChanged they cause in BlueZ (gdbus defers signals), here
//   the signals come first; Pair, ConnectProfile and DisconnectProfile answer NotSupported.

#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
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

namespace pitwall::testing {

namespace {

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
sdbus::Error bluezError(const std::string& name, const std::string& text) {
  return sdbus::Error("org.bluez.Error." + name, text);
}
sdbus::Error notReady() {
  return bluezError("NotReady", "Resource Not Ready");
}
sdbus::Error busy() {
  return bluezError("InProgress", "Operation already in progress");
}
sdbus::Error inProgress() {
  return bluezError("InProgress", "In Progress");
}
sdbus::Error notSupported() {
  return bluezError("NotSupported", "Operation is not supported");
}
sdbus::Error invalidArgs() {
  return bluezError("InvalidArguments", "Invalid arguments in method call");
}
sdbus::Error doesNotExist() {
  return bluezError("DoesNotExist", "Does Not Exist");
}
sdbus::Error notConnected() {
  return bluezError("NotConnected", "Not Connected");
}
sdbus::Error notPermitted(const std::string& text) {
  return bluezError("NotPermitted", text);
}
sdbus::Error failed(const std::string& text) {
  return bluezError("Failed", text);
}
const char* const kConnectionAborted = "le-connection-abort-by-local";

// "e0:00:00:00:00:01" → "E0:00:00:00:00:01"; throws std::invalid_argument.
std::string normalizeAddress(std::string_view text) {
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

std::string defaultAddress(int index) {
  char buf[18];
  std::snprintf(buf, sizeof buf, "E0:00:00:00:%02X:%02X", ((index + 1) >> 8) & 0xff,
                (index + 1) & 0xff);
  return buf;
}

// A UUID as BlueZ compares them: 128-bit, lower case (adapter.c parse_uuids). nullopt: invalid.
std::optional<std::string> uuid128(std::string_view text) {
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
std::optional<DiscoveryFilter> parseFilter(const Dict& dict) {
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

bool validUtf8(std::string_view s) {
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

void closeIo(std::unique_ptr<Io>& io) {
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

  // Faults.
  bool refused = false;
  bool vanished = false;
  std::optional<TimePoint> firstConnect;
  std::vector<std::pair<FakeBluez::Fault, Duration>> scheduled;

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

}  // namespace

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
  void finishConnect(Device& d);
  void failConnect(Device& d, const std::string& why);
  void linkUp(Device& d);
  void linkDown(Device& d, bool tellCar);
  void forget(Device& d);
  void toCar(Device& d, std::span<const std::uint8_t> frame);
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
  void arm(Device& d, Fault fault, Duration after);
};

FakeBluez::State::State(Loop& loop_, sdbus::IConnection& connection, Options options_)
    : loop(loop_),
      conn(connection),
      options(std::move(options_)),
      pump(loop_, connection),
      rng(options.seed * 0x9e3779b97f4a7c15ull + 1) {
  // No adapter is a machine without Bluetooth hardware, where bluetoothd still runs.
  if (options.adapters < 0 || (options.adapters == 0 && options.cars > 0))
    throw std::invalid_argument("cars need an adapter: " + std::to_string(options.adapters) +
                                " adapters for " + std::to_string(options.cars) + " cars");
  if (options.cars < 0)
    throw std::invalid_argument("the number of cars cannot be negative (" +
                                std::to_string(options.cars) + ")");
  if (options.addresses.size() > static_cast<std::size_t>(options.cars))
    throw std::invalid_argument(std::to_string(options.addresses.size()) + " addresses for " +
                                std::to_string(options.cars) +
                                " cars: give at most one address per car");
  if (options.names.size() > static_cast<std::size_t>(options.cars))
    throw std::invalid_argument(std::to_string(options.names.size()) + " names for " +
                                std::to_string(options.cars) +
                                " cars: give at most one name per car");
  auto track = sim::loadLayout(options.track);
  if (!track) throw std::invalid_argument(track.error());
  world = std::make_unique<sim::World>(loop, std::move(track.value()), options.seed);

  for (int i = 0; i < options.adapters; ++i) {
    auto a = std::make_unique<Adapter>();
    a->index = i;
    a->path = "/org/bluez/hci" + std::to_string(i);
    char buf[18];
    std::snprintf(buf, sizeof buf, "00:1A:7D:DA:71:%02X", i & 0xff);
    a->address = buf;
    a->name = "pitwall-fake-hci" + std::to_string(i);
    adapters.push_back(std::move(a));
  }

  std::vector<std::string> taken;
  for (int i = 0; i < options.cars; ++i) {
    sim::CarSpec spec = sim::gridSpec(world->track(), i);
    spec.name = static_cast<std::size_t>(i) < options.names.size()
                    ? options.names[i]
                    : sim::uniqueCarName(spec.model_id, taken);
    taken.push_back(spec.name);
    auto d = std::make_unique<Device>();
    d->index = i;
    d->address = static_cast<std::size_t>(i) < options.addresses.size()
                     ? normalizeAddress(options.addresses[i])
                     : defaultAddress(i);
    for (const auto& other : devices)
      if (other->address == d->address)
        throw std::invalid_argument("two cars have the address " + d->address +
                                    ": give each car its own");
    d->adapter = adapters[i % adapters.size()].get();
    std::string tail = d->address;
    std::replace(tail.begin(), tail.end(), ':', '_');
    d->path = d->adapter->path + "/dev_" + tail;
    d->car = &world->addCar(spec);
    d->baseRssi = static_cast<std::int16_t>(-50 - 6 * (i % 6));
    devices.push_back(std::move(d));
  }

  root = sdbus::createObject(conn, "/");
  root->addObjectManager();
  for (auto& a : adapters) exportAdapter(*a);

  // Discovery and notify sessions belong to the bus connection that started them.
  nameWatch = conn.addMatch(
      "type='signal',sender='org.freedesktop.DBus',path='/org/freedesktop/DBus',"
      "interface='org.freedesktop.DBus',member='NameOwnerChanged'",
      [this](sdbus::Message& m) {
        std::string name, oldOwner, newOwner;
        m >> name >> oldOwner >> newOwner;
        if (newOwner.empty() && !name.empty() && name[0] == ':') clientGone(name);
      });

  // Last: a client that sees org.bluez appear finds every object in place.
  try {
    conn.requestName("org.bluez");
  } catch (const sdbus::Error& e) {
    if (e.getName().find("EALREADY") == std::string::npos) {
      throw sdbus::Error(e.getName(), "cannot own org.bluez on this bus (" + e.getMessage() +
                                          "): is another BlueZ (or fake) running there?");
    }
  }
  pump.kick();
}

FakeBluez::State::~State() {
  alive.reset();
  for (auto id : timers) loop.cancel(id);
  timers.clear();
  nameWatch.reset();
  for (auto& d : devices) {
    if (d->connected) d->car->disconnect();  // without telling us: we are going away
    if (d->readChar) closeIo(d->readChar->notifyIo);
    if (d->writeChar) closeIo(d->writeChar->writeIo);
    d->readChar.reset();
    d->writeChar.reset();
    d->service.reset();
    d->object.reset();
  }
  for (auto& a : adapters) a->object.reset();
  root.reset();
  world.reset();
}

Loop::TimerId FakeBluez::State::after(Duration delay, std::function<void()> fn) {
  auto self = std::make_shared<Loop::TimerId>(0);
  *self = loop.after(delay, [this, self, fn = std::move(fn)] {
    timers.erase(*self);
    fn();
    pump.kick();
  });
  timers.insert(*self);
  return *self;
}

void FakeBluez::State::cancel(Loop::TimerId& id) {
  if (!id) return;
  loop.cancel(id);
  timers.erase(id);
  id = 0;
}

void FakeBluez::State::later(std::function<void()> fn) {
  std::weak_ptr<bool> a = alive;
  loop.post([this, a, fn = std::move(fn)] {
    if (a.expired()) return;
    fn();
    pump.kick();
  });
}

Device& FakeBluez::State::device(std::string_view address) {
  return const_cast<Device&>(std::as_const(*this).device(address));
}

const Device& FakeBluez::State::device(std::string_view address) const {
  // Any case, compared in place: inject() is on the benchmarks' measured path.
  auto same = [](char a, char b) {
    return std::toupper(static_cast<unsigned char>(a)) == static_cast<unsigned char>(b);
  };
  for (const auto& d : devices)
    if (std::equal(address.begin(), address.end(), d->address.begin(), d->address.end(), same))
      return *d;
  throw std::out_of_range("the fake has no car with the address '" + std::string(address) + "'");
}

void FakeBluez::State::emit(sdbus::IObject* object, const char* iface,
                            const std::vector<std::string>& props) {
  if (object) object->emitPropertiesChangedSignal(iface, props);
}

// ---- adapters ----

void FakeBluez::State::exportAdapter(Adapter& a) {
  auto o = sdbus::createObject(conn, a.path);
  sdbus::IObject* obj = o.get();
  Adapter* ap = &a;
  auto sender = [obj] { return obj->getCurrentlyProcessedMessage()->getSender(); };

  obj->registerMethod("StartDiscovery")
      .onInterface(api::kAdapter)
      .implementedAs([this, ap, sender] { startDiscovery(*ap, sender()); });
  obj->registerMethod("StopDiscovery").onInterface(api::kAdapter).implementedAs([this, ap, sender] {
    stopDiscovery(*ap, sender());
  });
  obj->registerMethod("SetDiscoveryFilter")
      .onInterface(api::kAdapter)
      .withInputParamNames("properties")
      .implementedAs([ap, sender](const Dict& dict) {
        if (!ap->powered) throw notReady();
        auto filter = parseFilter(dict);
        std::string who = sender();
        auto it = ap->clients.find(who);
        if (it != ap->clients.end()) {
          it->second.filter = filter;
          if (!filter && !it->second.discovering) ap->clients.erase(it);  // pre-set filter cleared
        } else if (filter) {
          ap->clients[who].filter = filter;  // pre-set for a later StartDiscovery
        }
      });
  obj->registerMethod("GetDiscoveryFilters")
      .onInterface(api::kAdapter)
      .withOutputParamNames("filters")
      .implementedAs([] {
        return std::vector<std::string>{"UUIDs",         "RSSI",         "Pathloss", "Transport",
                                        "DuplicateData", "Discoverable", "Pattern"};
      });
  obj->registerMethod("RemoveDevice")
      .onInterface(api::kAdapter)
      .withInputParamNames("device")
      .implementedAs([this, ap](const sdbus::ObjectPath& path) {
        for (auto& d : devices) {
          if (d->adapter == ap && d->object && d->path == path) {
            forget(*d);
            return;
          }
        }
        throw doesNotExist();
      });

  obj->registerProperty("Address").onInterface(api::kAdapter).withGetter([ap] {
    return ap->address;
  });
  obj->registerProperty("AddressType").onInterface(api::kAdapter).withGetter([] {
    return std::string("public");
  });
  obj->registerProperty("Name").onInterface(api::kAdapter).withGetter([ap] { return ap->name; });
  obj->registerProperty("Alias")
      .onInterface(api::kAdapter)
      .withGetter([ap] { return ap->alias.empty() ? ap->name : ap->alias; })
      .withSetter([this, ap](const std::string& v) {
        ap->alias = v;  // "" restores the system name
        emit(ap->object.get(), api::kAdapter, {"Alias"});
      });
  obj->registerProperty("Class").onInterface(api::kAdapter).withGetter([] {
    return std::uint32_t{0};
  });
  obj->registerProperty("Powered")
      .onInterface(api::kAdapter)
      .withGetter([ap] { return ap->powered; })
      .withSetter([this, ap](const bool& on) {
        if (on == ap->powered) return;
        ap->powered = on;
        if (!on) {
          // Powering off ends discovery and every connection of this controller.
          ap->clients.clear();
          if (ap->discovering) stopScan(*ap);
          for (auto& d : devices) {
            if (d->adapter != ap) continue;
            if (d->connecting) failConnect(*d, "Not Powered");
            linkDown(*d, true);
          }
        }
        emit(ap->object.get(), api::kAdapter, {"Powered"});
      });
  obj->registerProperty("Discoverable")
      .onInterface(api::kAdapter)
      .withGetter([ap] { return ap->discoverable; })
      .withSetter([this, ap](const bool& v) {
        ap->discoverable = v;
        emit(ap->object.get(), api::kAdapter, {"Discoverable"});
      });
  obj->registerProperty("DiscoverableTimeout").onInterface(api::kAdapter).withGetter([] {
    return std::uint32_t{180};
  });
  obj->registerProperty("Pairable")
      .onInterface(api::kAdapter)
      .withGetter([ap] { return ap->pairable; })
      .withSetter([this, ap](const bool& v) {
        ap->pairable = v;
        emit(ap->object.get(), api::kAdapter, {"Pairable"});
      });
  obj->registerProperty("PairableTimeout").onInterface(api::kAdapter).withGetter([] {
    return std::uint32_t{0};
  });
  obj->registerProperty("Discovering").onInterface(api::kAdapter).withGetter([ap] {
    return ap->discovering;
  });
  obj->registerProperty("UUIDs").onInterface(api::kAdapter).withGetter([] {
    return std::vector<std::string>{"00001801-0000-1000-8000-00805f9b34fb",   // GATT
                                    "00001800-0000-1000-8000-00805f9b34fb",   // GAP
                                    "0000180a-0000-1000-8000-00805f9b34fb"};  // Device Info
  });
  obj->registerProperty("Modalias").onInterface(api::kAdapter).withGetter([] {
    return std::string("usb:v1D6Bp0246d0542");  // BlueZ 5.66
  });
  obj->registerProperty("Roles").onInterface(api::kAdapter).withGetter([] {
    return std::vector<std::string>{"central", "peripheral"};
  });
  obj->finishRegistration();
  a.object = std::move(o);
}

// ---- discovery ----

void FakeBluez::State::startDiscovery(Adapter& a, const std::string& sender) {
  if (!a.powered) throw notReady();
  auto it = a.clients.find(sender);
  if (it != a.clients.end() && it->second.discovering) throw busy();  // one per client
  a.clients[sender].discovering = true;
  log::debug(kComponent, a.path + ": discovery started by " + sender);
  if (!a.discovering) startScan(a);
}

void FakeBluez::State::stopDiscovery(Adapter& a, const std::string& sender) {
  if (!a.powered) throw notReady();
  auto it = a.clients.find(sender);
  if (it == a.clients.end() || !it->second.discovering) throw failed("No discovery started");
  a.clients.erase(it);  // the client's filter goes with it (adapter.c discovery_stop)
  log::debug(kComponent, a.path + ": discovery stopped by " + sender);
  if (a.discovering && !a.anyDiscovering()) stopScan(a);
}

void FakeBluez::State::startScan(Adapter& a) {
  a.discovering = true;
  emit(a.object.get(), api::kAdapter, {"Discovering"});
  Adapter* ap = &a;
  int k = 0;
  for (auto& d : devices) {
    if (d->adapter != ap) continue;
    Device* dp = d.get();
    a.sightings.push_back(after(kFirstSeen + k * kSeenSpacing, [this, dp] { advertise(*dp); }));
    ++k;
  }
  armAdvertTick(a);
}

// One periodic timer per adapter while it discovers: each firing is an advertisement of every car.
void FakeBluez::State::armAdvertTick(Adapter& a) {
  Adapter* ap = &a;
  a.advertTimer = after(kAdvertPeriod, [this, ap] {
    ap->advertTimer = 0;
    for (auto& d : devices)
      if (d->adapter == ap) advertise(*d);
    if (ap->discovering) armAdvertTick(*ap);
  });
}

void FakeBluez::State::stopScan(Adapter& a) {
  a.discovering = false;
  for (auto& id : a.sightings) cancel(id);
  a.sightings.clear();
  cancel(a.advertTimer);
  for (auto& d : devices)
    if (d->adapter == &a) d->rssiStale = true;
  emit(a.object.get(), api::kAdapter, {"Discovering"});
}

bool FakeBluez::State::wanted(const Adapter& a, const Device& d, std::int16_t rssi,
                              const std::string& name) const {
  // A device is reported when any discovering client's filter lets it through
  // (adapter.c is_filter_match); a client without a filter takes everything.
  for (const auto& [who, c] : a.clients) {
    if (!c.discovering) continue;
    if (!c.filter) return true;
    const DiscoveryFilter& f = *c.filter;
    if (f.transport == "bredr") continue;  // the cars are LE only
    if (!f.uuids.empty() &&
        std::find(f.uuids.begin(), f.uuids.end(), anki::kServiceUuid) == f.uuids.end())
      continue;
    if (f.rssi && rssi < *f.rssi) continue;
    if (f.pathloss && kTxPower - rssi > *f.pathloss) continue;
    if (!f.pattern.empty() && d.address.rfind(f.pattern, 0) != 0 && name.rfind(f.pattern, 0) != 0)
      continue;
    return true;
  }
  return false;
}

void FakeBluez::State::advertise(Device& d) {
  Adapter& a = *d.adapter;
  // A connected car does not advertise; a vanished one never again.
  if (!a.discovering || !a.powered || d.vanished || d.connected) return;
  std::uniform_int_distribution<int> jitter(-12, 12);
  auto rssi = static_cast<std::int16_t>(d.baseRssi + jitter(rng));
  auto manufacturer = d.car->manufacturerData();
  auto localName = d.car->localName();
  std::string name = FakeBluez::bluezName(localName);
  if (!wanted(a, d, rssi, name)) return;

  if (!d.object) {
    d.rssi = rssi;
    d.manufacturer = std::move(manufacturer);
    d.localName = std::move(localName);
    d.name = std::move(name);
    exportDevice(d);
    return;
  }
  std::vector<std::string> changed;
  if (d.rssiStale || std::abs(rssi - d.rssi) >= kRssiThreshold) {
    d.rssiStale = false;
    d.rssi = rssi;
    changed.push_back("RSSI");
  }
  if (manufacturer != d.manufacturer) {
    d.manufacturer = std::move(manufacturer);
    changed.push_back("ManufacturerData");
  }
  if (localName != d.localName) {
    d.localName = std::move(localName);
    changed.push_back("AdvertisingData");
    // The Name property exists or not from the first sighting on (sdbus-c++ cannot add one).
    if (d.hasName && !name.empty() && name != d.name) {
      d.name = name;
      changed.push_back("Name");
      if (d.alias.empty()) changed.push_back("Alias");
    }
  }
  if (!changed.empty()) emit(d.object.get(), api::kDevice, changed);
}

void FakeBluez::State::clientGone(const std::string& uniqueName) {
  for (auto& a : adapters) {
    if (a->clients.erase(uniqueName) && a->discovering && !a->anyDiscovering()) {
      log::debug(kComponent, a->path + ": discovery ends, " + uniqueName + " left the bus");
      stopScan(*a);
    }
  }
  for (auto& d : devices) {
    Characteristic* ch = d->readChar.get();
    if (ch && ch->notifySessions.erase(uniqueName) && ch->notifySessions.empty())
      emit(ch->object.get(), api::kGattCharacteristic, {"Notifying"});
  }
}

// ---- devices ----

void FakeBluez::State::exportDevice(Device& d) {
  auto o = sdbus::createObject(conn, d.path);
  sdbus::IObject* obj = o.get();
  Device* dp = &d;

  obj->registerMethod("Connect")
      .onInterface(api::kDevice)
      .implementedAs([this, dp](sdbus::Result<>&& result) { connect(*dp, std::move(result)); });
  obj->registerMethod("Disconnect").onInterface(api::kDevice).implementedAs([this, dp] {
    if (!dp->connected) throw notConnected();
    log::debug(kComponent, dp->address + ": disconnected by the client");
    linkDown(*dp, true);
  });
  for (const char* m : {"ConnectProfile", "DisconnectProfile"}) {
    obj->registerMethod(m)
        .onInterface(api::kDevice)
        .withInputParamNames("UUID")
        .implementedAs([](const std::string&) { throw notSupported(); });
  }
  obj->registerMethod("Pair").onInterface(api::kDevice).implementedAs([] { throw notSupported(); });
  obj->registerMethod("CancelPairing").onInterface(api::kDevice).implementedAs([] {
    throw doesNotExist();
  });

  obj->registerProperty("Address").onInterface(api::kDevice).withGetter([dp] {
    return dp->address;
  });
  obj->registerProperty("AddressType").onInterface(api::kDevice).withGetter([] {
    return std::string("random");
  });
  d.hasName = !d.name.empty();
  if (d.hasName)
    obj->registerProperty("Name").onInterface(api::kDevice).withGetter([dp] { return dp->name; });
  obj->registerProperty("Alias")
      .onInterface(api::kDevice)
      .withGetter([dp] { return dp->currentAlias(); })
      .withSetter([this, dp](const std::string& v) {
        dp->alias = v;  // "" goes back to the name (or the address)
        emit(dp->object.get(), api::kDevice, {"Alias"});
      });
  obj->registerProperty("Adapter").onInterface(api::kDevice).withGetter([dp] {
    return sdbus::ObjectPath(dp->adapter->path);
  });
  obj->registerProperty("UUIDs").onInterface(api::kDevice).withGetter([] {
    return std::vector<std::string>{std::string(anki::kServiceUuid)};
  });
  obj->registerProperty("ManufacturerData").onInterface(api::kDevice).withGetter([dp] {
    // BlueZ splits the first two bytes off as the company id, little-endian: BE EF → 0xEFBE.
    std::map<std::uint16_t, sdbus::Variant> out;
    const auto& m = dp->manufacturer;
    if (m.size() >= 2) {
      auto key = static_cast<std::uint16_t>(m[0] | (m[1] << 8));
      out[key] = sdbus::Variant(std::vector<std::uint8_t>(m.begin() + 2, m.end()));
    }
    return out;
  });
  obj->registerProperty("AdvertisingData").onInterface(api::kDevice).withGetter([dp] {
    std::map<std::uint8_t, sdbus::Variant> out;
    out[0x09] = sdbus::Variant(dp->localName);  // Complete Local Name, raw
    return out;
  });
  obj->registerProperty("AdvertisingFlags").onInterface(api::kDevice).withGetter([] {
    return std::vector<std::uint8_t>{0x06};  // LE General Discoverable, BR/EDR not supported
  });
  obj->registerProperty("RSSI").onInterface(api::kDevice).withGetter([dp] { return dp->rssi; });
  obj->registerProperty("TxPower").onInterface(api::kDevice).withGetter([] { return kTxPower; });
  obj->registerProperty("Connected").onInterface(api::kDevice).withGetter([dp] {
    return dp->connected;
  });
  obj->registerProperty("ServicesResolved").onInterface(api::kDevice).withGetter([dp] {
    return dp->resolved;
  });
  obj->registerProperty("Paired").onInterface(api::kDevice).withGetter([] { return false; });
  obj->registerProperty("LegacyPairing").onInterface(api::kDevice).withGetter([] { return false; });
  obj->registerProperty("Trusted")
      .onInterface(api::kDevice)
      .withGetter([dp] { return dp->trusted; })
      .withSetter([this, dp](const bool& v) {
        dp->trusted = v;
        emit(dp->object.get(), api::kDevice, {"Trusted"});
      });
  obj->registerProperty("Blocked")
      .onInterface(api::kDevice)
      .withGetter([dp] { return dp->blocked; })
      .withSetter([this, dp](const bool& v) {
        dp->blocked = v;
        emit(dp->object.get(), api::kDevice, {"Blocked"});
      });
  obj->finishRegistration();
  d.object = std::move(o);
  d.object->emitInterfacesAddedSignal();
  log::debug(kComponent, d.address + ": discovered on " + d.adapter->path);
}

void FakeBluez::State::unexportDevice(Device& d) {
  if (!d.object) return;
  d.object->emitInterfacesRemovedSignal();
  d.object.reset();
  d.alias.clear();  // BlueZ forgets what it stored about a removed device
  d.trusted = d.blocked = false;
}

// RemoveDevice: disconnect if needed, then the object goes; the next advertisement brings it back.
void FakeBluez::State::forget(Device& d) {
  if (d.connecting) failConnect(d, kConnectionAborted);
  linkDown(d, true);
  unexportDevice(d);
  log::debug(kComponent, d.address + ": removed");
}

// ---- GATT ----

std::unique_ptr<Characteristic> FakeBluez::State::makeCharacteristic(
    Device& d, const std::string& path, std::string_view uuid, std::vector<std::string> flags) {
  auto ch = std::make_unique<Characteristic>();
  ch->path = path;
  ch->uuid = std::string(uuid);
  ch->flags = std::move(flags);
  auto has = [&](const char* f) {
    return std::find(ch->flags.begin(), ch->flags.end(), f) != ch->flags.end();
  };
  ch->notify = has("notify");
  ch->writeCommand = has("write-without-response");
  ch->writeRequest = has("write");

  auto o = sdbus::createObject(conn, path);
  sdbus::IObject* obj = o.get();
  Device* dp = &d;
  Characteristic* cp = ch.get();
  std::string servicePath = d.path + "/service000a";

  obj->registerMethod("ReadValue")
      .onInterface(api::kGattCharacteristic)
      .withInputParamNames("options")
      .withOutputParamNames("value")
      .implementedAs([this, dp, cp](const Dict& options) { return readValue(*dp, *cp, options); });
  obj->registerMethod("WriteValue")
      .onInterface(api::kGattCharacteristic)
      .withInputParamNames("value", "options")
      .implementedAs([this, dp, cp](const std::vector<std::uint8_t>& value, const Dict& options) {
        writeValue(*dp, *cp, value, options);
      });
  obj->registerMethod("AcquireWrite")
      .onInterface(api::kGattCharacteristic)
      .withInputParamNames("options")
      .withOutputParamNames("fd", "mtu")
      .implementedAs([this, dp, cp](const Dict&) { return acquire(*dp, *cp, true); });
  obj->registerMethod("AcquireNotify")
      .onInterface(api::kGattCharacteristic)
      .withInputParamNames("options")
      .withOutputParamNames("fd", "mtu")
      .implementedAs([this, dp, cp](const Dict&) { return acquire(*dp, *cp, false); });
  obj->registerMethod("StartNotify")
      .onInterface(api::kGattCharacteristic)
      .implementedAs([this, dp, cp] { startNotify(*dp, *cp); });
  obj->registerMethod("StopNotify").onInterface(api::kGattCharacteristic).implementedAs([this, cp] {
    stopNotify(*cp);
  });

  obj->registerProperty("UUID").onInterface(api::kGattCharacteristic).withGetter([cp] {
    return cp->uuid;
  });
  obj->registerProperty("Service").onInterface(api::kGattCharacteristic).withGetter([servicePath] {
    return sdbus::ObjectPath(servicePath);
  });
  obj->registerProperty("Value").onInterface(api::kGattCharacteristic).withGetter([cp] {
    return cp->value;
  });
  obj->registerProperty("Flags").onInterface(api::kGattCharacteristic).withGetter([cp] {
    return cp->flags;
  });
  // Like gatt-client.c, the notify and acquire properties exist only where the flags allow.
  if (ch->notify) {
    obj->registerProperty("Notifying").onInterface(api::kGattCharacteristic).withGetter([cp] {
      return !cp->notifySessions.empty();
    });
    obj->registerProperty("NotifyAcquired").onInterface(api::kGattCharacteristic).withGetter([cp] {
      return cp->notifyIo != nullptr;
    });
  }
  if (ch->writeCommand) {
    obj->registerProperty("WriteAcquired").onInterface(api::kGattCharacteristic).withGetter([cp] {
      return cp->writeIo != nullptr;
    });
  }
  obj->registerProperty("MTU").onInterface(api::kGattCharacteristic).withGetter([] {
    return kMtu;
  });
  obj->finishRegistration();
  ch->object = std::move(o);
  return ch;
}

void FakeBluez::State::exportGatt(Device& d) {
  std::string servicePath = d.path + "/service000a";
  auto s = sdbus::createObject(conn, servicePath);
  Device* dp = &d;
  s->registerProperty("UUID").onInterface(api::kGattService).withGetter([] {
    return std::string(anki::kServiceUuid);
  });
  s->registerProperty("Primary").onInterface(api::kGattService).withGetter([] { return true; });
  s->registerProperty("Device").onInterface(api::kGattService).withGetter([dp] {
    return sdbus::ObjectPath(dp->path);
  });
  s->registerProperty("Includes").onInterface(api::kGattService).withGetter([] {
    return std::vector<sdbus::ObjectPath>{};
  });
  s->finishRegistration();
  d.service = std::move(s);
  d.readChar =
      makeCharacteristic(d, servicePath + "/char000b", anki::kReadCharUuid, {"read", "notify"});
  d.writeChar = makeCharacteristic(d, servicePath + "/char000d", anki::kWriteCharUuid,
                                   {"read", "write-without-response", "write"});
  d.service->emitInterfacesAddedSignal();
  d.readChar->object->emitInterfacesAddedSignal();
  d.writeChar->object->emitInterfacesAddedSignal();
}

void FakeBluez::State::removeGatt(Device& d) {
  for (Characteristic* ch : {d.readChar.get(), d.writeChar.get()}) {
    if (!ch) continue;
    closeIo(ch->notifyIo);
    closeIo(ch->writeIo);
    ch->object->emitInterfacesRemovedSignal();
  }
  d.readChar.reset();
  d.writeChar.reset();
  if (d.service) d.service->emitInterfacesRemovedSignal();
  d.service.reset();
}

std::vector<std::uint8_t> FakeBluez::State::readValue(Device& d, Characteristic& ch,
                                                      const Dict& options) {
  if (!d.connected) throw failed("Not connected");
  std::uint16_t offset = 0;
  if (auto it = options.find("offset"); it != options.end()) {
    if (!it->second.containsValueOfType<std::uint16_t>()) throw invalidArgs();
    offset = it->second.get<std::uint16_t>();
  }
  if (offset > ch.value.size()) throw bluezError("InvalidOffset", "Invalid offset");
  return std::vector<std::uint8_t>(ch.value.begin() + offset, ch.value.end());
}

void FakeBluez::State::writeValue(Device& d, Characteristic& ch,
                                  const std::vector<std::uint8_t>& value, const Dict& options) {
  // gatt-client.c characteristic_write_value.
  if (!d.connected) throw failed("Not connected");
  if (ch.writeIo) throw notPermitted("Write acquired");
  std::string type;
  std::uint16_t offset = 0;
  if (auto it = options.find("type"); it != options.end()) {
    if (!it->second.containsValueOfType<std::string>()) throw invalidArgs();
    type = it->second.get<std::string>();
    std::transform(type.begin(), type.end(), type.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  }
  if (auto it = options.find("offset"); it != options.end()) {
    if (!it->second.containsValueOfType<std::uint16_t>()) throw invalidArgs();
    offset = it->second.get<std::uint16_t>();
  }
  bool request;
  if (type.empty()) {
    if (ch.writeRequest)
      request = true;
    else if (ch.writeCommand && offset == 0)
      request = false;
    else
      throw notSupported();
  } else if (type == "request") {
    request = true;
  } else if (type == "command") {
    if (!ch.writeCommand || offset) throw notSupported();
    request = false;
  } else {
    throw notSupported();  // "reliable" needs the reliable-write extended property
  }
  if (request && !ch.writeRequest)
    throw notPermitted("Write not permitted");  // the car's ATT error
  if (!request && value.size() > kMtu - 3u) throw failed("Failed to initiate write");
  toCar(d, value);
}

std::tuple<sdbus::UnixFd, std::uint16_t> FakeBluez::State::acquire(Device& d, Characteristic& ch,
                                                                   bool write) {
  // gatt-client.c characteristic_acquire_write / _notify, create_sock.
  if (options.noAcquire) throw notSupported();
  if (!d.connected) throw failed("Not connected");
  if (write) {
    if (ch.writeIo) throw notPermitted("Write acquired");
    if (!ch.writeCommand) throw notSupported();
  } else {
    if (ch.notifyIo) throw notPermitted("Notify acquired");
    if (!ch.notifySessions.empty()) throw inProgress();
    if (!ch.notify) throw notSupported();
  }
  int fds[2];
  if (::socketpair(AF_LOCAL, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, fds) < 0)
    throw failed(std::strerror(errno));
  if (write) {
    ch.writeIo = std::make_unique<Io>(loop.io(), fds[0]);
    watchWriteIo(d, ch);
    emit(ch.object.get(), api::kGattCharacteristic, {"WriteAcquired"});
  } else {
    ch.notifyIo = std::make_unique<Io>(loop.io(), fds[0]);
    watchNotifyIo(d, ch);
    emit(ch.object.get(), api::kGattCharacteristic, {"NotifyAcquired"});
  }
  log::debug(kComponent, d.address + (write ? ": write" : ": notify") + " socket acquired");
  return {sdbus::UnixFd(fds[1], sdbus::adopt_fd), kMtu};
}

void FakeBluez::State::watchNotifyIo(Device& d, Characteristic& ch) {
  std::weak_ptr<int> token = ch.notifyIo->token;
  Device* dp = &d;
  Characteristic* cp = &ch;
  ch.notifyIo->fd.async_wait(boost::asio::posix::stream_descriptor::wait_read,
                             [this, dp, cp, token](const boost::system::error_code& ec) {
                               if (token.expired() || ec) return;
                               // The client has nothing to send here: readable means it closed.
                               std::uint8_t buf[64];
                               ssize_t n;
                               int fd = cp->notifyIo->fd.native_handle();
                               while ((n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT)) > 0) {
                               }
                               if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) {
                                 closeNotifyIo(*cp);
                                 pump.kick();
                                 return;
                               }
                               watchNotifyIo(*dp, *cp);
                             });
}

void FakeBluez::State::watchWriteIo(Device& d, Characteristic& ch) {
  std::weak_ptr<int> token = ch.writeIo->token;
  Device* dp = &d;
  Characteristic* cp = &ch;
  ch.writeIo->fd.async_wait(boost::asio::posix::stream_descriptor::wait_read,
                            [this, dp, cp, token](const boost::system::error_code& ec) {
                              if (token.expired() || ec) return;
                              std::uint8_t buf[512];
                              for (;;) {
                                ssize_t n = ::recv(cp->writeIo->fd.native_handle(), buf, sizeof buf,
                                                   MSG_DONTWAIT);
                                if (n > 0) {
                                  toCar(*dp, std::span<const std::uint8_t>(buf, n));
                                  if (token.expired()) return pump.kick();
                                  continue;
                                }
                                if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) {
                                  closeWriteIo(*cp);  // the client closed its end
                                  return pump.kick();
                                }
                                break;
                              }
                              pump.kick();
                              watchWriteIo(*dp, *cp);
                            });
}

void FakeBluez::State::closeNotifyIo(Characteristic& ch) {
  if (!ch.notifyIo) return;
  closeIo(ch.notifyIo);
  emit(ch.object.get(), api::kGattCharacteristic, {"NotifyAcquired"});
}

void FakeBluez::State::closeWriteIo(Characteristic& ch) {
  if (!ch.writeIo) return;
  closeIo(ch.writeIo);
  emit(ch.object.get(), api::kGattCharacteristic, {"WriteAcquired"});
}

void FakeBluez::State::startNotify(Device& d, Characteristic& ch) {
  // gatt-client.c characteristic_start_notify.
  if (!d.connected) throw notConnected();
  if (ch.notifyIo) throw notPermitted("Notify acquired");
  if (!ch.notify) throw notSupported();
  std::string sender = ch.object->getCurrentlyProcessedMessage()->getSender();
  if (!ch.notifySessions.insert(sender).second) return;  // one session per client
  if (ch.notifySessions.size() == 1) emit(ch.object.get(), api::kGattCharacteristic, {"Notifying"});
}

void FakeBluez::State::stopNotify(Characteristic& ch) {
  if (ch.notifyIo) {
    closeNotifyIo(ch);
    return;
  }
  std::string sender = ch.object->getCurrentlyProcessedMessage()->getSender();
  if (!ch.notifySessions.erase(sender)) throw failed("No notify session started");
  if (ch.notifySessions.empty()) emit(ch.object.get(), api::kGattCharacteristic, {"Notifying"});
}

// ---- links ----

void FakeBluez::State::connect(Device& d, sdbus::Result<>&& result) {
  ++d.counters.connectCalls;
  if (!d.adapter->powered) return result.returnError(notReady());
  if (d.connected) return result.returnResults();  // device.c: already connected over LE
  if (d.connecting) return result.returnError(inProgress());
  d.connecting = true;
  d.pendingConnect = std::make_shared<sdbus::Result<>>(std::move(result));
  Device* dp = &d;
  d.connectTimer = after(kConnectDelay, [this, dp] {
    dp->connectTimer = 0;
    finishConnect(*dp);
  });
}

void FakeBluez::State::finishConnect(Device& d) {
  if (d.refused) {
    log::debug(kComponent, d.address + ": connection refused (fault)");
    return failConnect(d, kConnectionAborted);
  }
  linkUp(d);
}

void FakeBluez::State::failConnect(Device& d, const std::string& why) {
  cancel(d.connectTimer);
  d.connecting = false;
  auto pending = std::move(d.pendingConnect);
  if (pending) pending->returnError(failed(why));
}

void FakeBluez::State::linkUp(Device& d) {
  d.connecting = false;
  d.connected = true;
  ++d.generation;
  ++d.counters.connects;
  emit(d.object.get(), api::kDevice, {"Connected"});
  exportGatt(d);  // services come with the link; ServicesResolved says when they are complete

  Device* dp = &d;
  std::uint64_t generation = d.generation;
  std::weak_ptr<bool> a = alive;
  d.car->connect(
      [this, dp, generation](std::span<const std::uint8_t> frame) {
        if (dp->generation != generation || !dp->connected) return;
        if (toClient(*dp, frame)) pump.kick();
      },
      [this, a, dp, generation] {
        // The car hung up (it got a disconnect frame, or went away): the link is gone. Later,
        // not now: we may be inside a method handler of an object this tears down.
        if (a.expired()) return;
        later([this, dp, generation] {
          if (dp->generation != generation || !dp->connected) return;
          log::debug(kComponent, dp->address + ": the car dropped the connection");
          linkDown(*dp, false);
        });
      });

  auto pending = std::move(d.pendingConnect);
  if (pending) pending->returnResults();
  d.resolveTimer = after(kResolveDelay, [this, dp] {
    dp->resolveTimer = 0;
    dp->resolved = true;
    emit(dp->object.get(), api::kDevice, {"ServicesResolved"});
  });
  log::debug(kComponent, d.address + ": connected");

  if (!d.firstConnect) {
    d.firstConnect = loop.now();
    for (const auto& [fault, delay] : d.scheduled) arm(d, fault, delay);
  }
}

void FakeBluez::State::linkDown(Device& d, bool tellCar) {
  if (!d.connected) return;
  d.connected = false;
  d.resolved = false;
  ++d.generation;
  ++d.counters.disconnects;
  cancel(d.resolveTimer);
  removeGatt(d);
  emit(d.object.get(), api::kDevice, {"ServicesResolved", "Connected"});
  if (tellCar) d.car->disconnect();  // the car stops, as on a lost link
}

void FakeBluez::State::toCar(Device& d, std::span<const std::uint8_t> frame) {
  ++d.counters.framesToCar;
  d.car->receive(frame);
}

bool FakeBluez::State::toClient(Device& d, std::span<const std::uint8_t> frame) {
  Characteristic* ch = d.readChar.get();
  if (!ch) {
    ++d.counters.framesDropped;
    return false;
  }
  if (ch->notifyIo) {
    // One notification, one datagram (gatt-client.c notify_io_cb); a full socket loses it.
    ssize_t n = ::send(ch->notifyIo->fd.native_handle(), frame.data(), frame.size(),
                       MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0) {
      ++d.counters.framesDropped;
      if (errno == EPIPE || errno == ECONNRESET) closeNotifyIo(*ch);
      return false;
    }
    ++d.counters.framesToClient;
    return false;
  }
  if (!ch->notifySessions.empty()) {
    ch->value.assign(frame.begin(), frame.end());
    emit(ch->object.get(), api::kGattCharacteristic, {"Value"});
    ++d.counters.framesToClient;
    return true;
  }
  ++d.counters.framesDropped;
  return false;
}

// ---- faults ----

void FakeBluez::State::drop(Device& d) {
  if (d.connecting) failConnect(d, kConnectionAborted);
  if (d.connected) log::debug(kComponent, d.address + ": link dropped (fault)");
  linkDown(d, true);
}

void FakeBluez::State::vanish(Device& d) {
  d.vanished = true;
  drop(d);
  unexportDevice(d);
  log::debug(kComponent, d.address + ": vanished (fault)");
}

bool FakeBluez::State::inject(Device& d, std::span<const std::uint8_t> bytes) {
  if (!d.connected) {
    log::warn(kComponent, d.address + ": not connected, injected bytes dropped");
    return false;
  }
  return toClient(d, bytes);
}

void FakeBluez::State::arm(Device& d, Fault fault, Duration delay) {
  Duration wait = std::max(Duration::zero(), *d.firstConnect + delay - loop.now());
  Device* dp = &d;
  after(wait, [this, dp, fault] {
    switch (fault) {
      case Fault::Drop:
        drop(*dp);
        break;
      case Fault::Vanish:
        vanish(*dp);
        break;
      case Fault::Garbage:
        for (const auto& f : FakeBluez::garbageFrames()) inject(*dp, f);
        break;
    }
  });
}

// ---- FakeBluez ----

FakeBluez::FakeBluez(Loop& loop, sdbus::IConnection& connection, Options options)
    : state_(std::make_unique<State>(loop, connection, std::move(options))) {}

FakeBluez::~FakeBluez() = default;

sim::World& FakeBluez::world() {
  return *state_->world;
}
sim::SimCar& FakeBluez::car(std::string_view address) {
  return *state_->device(address).car;
}
std::vector<std::string> FakeBluez::addresses() const {
  std::vector<std::string> out;
  for (const auto& d : state_->devices) out.push_back(d->address);
  return out;
}
std::string FakeBluez::adapterPath(int index) const {
  return state_->adapters.at(static_cast<std::size_t>(index))->path;
}
std::string FakeBluez::devicePath(std::string_view address) const {
  return state_->device(address).path;
}
bool FakeBluez::exported(std::string_view address) const {
  return state_->device(address).object != nullptr;
}
bool FakeBluez::connected(std::string_view address) const {
  return state_->device(address).connected;
}
const FakeBluez::Counters& FakeBluez::counters(std::string_view address) const {
  return state_->device(address).counters;
}
DbusPump& FakeBluez::pump() {
  return state_->pump;
}

void FakeBluez::refuse(std::string_view address, bool refused) {
  state_->device(address).refused = refused;
}
void FakeBluez::drop(std::string_view address) {
  state_->drop(state_->device(address));
  state_->pump.kick();
}
void FakeBluez::vanish(std::string_view address) {
  state_->vanish(state_->device(address));
  state_->pump.kick();
}
void FakeBluez::inject(std::string_view address, std::span<const std::uint8_t> bytes) {
  // Only a D-Bus signal needs the pump; a frame written to an acquired socket does not.
  if (state_->inject(state_->device(address), bytes)) state_->pump.kick();
}
void FakeBluez::schedule(Fault fault, std::string_view address, Duration after) {
  Device& d = state_->device(address);
  d.scheduled.emplace_back(fault, after);
  if (d.firstConnect) state_->arm(d, fault, after);
}

std::vector<std::vector<std::uint8_t>> FakeBluez::garbageFrames() {
  return {
      {0x05, 0x17},              // the size byte promises 5 bytes, 1 follows
      {0x01},                    // a size byte and nothing else
      {0x03, 0x7e, 0x00, 0x00},  // a sane size, an id no firmware sends
  };
}

std::string FakeBluez::bluezName(std::span<const std::uint8_t> raw) {
  // eir.c name2utf8 (BlueZ 5.66): valid UTF-8 is taken whole; g_utf8_validate fails on any NUL,
  // so an Anki name goes the other way: strncpy (cut at the first NUL), non-ASCII bytes become
  // spaces, then g_strstrip. Control bytes below 0x80 (the Anki state bits) stay.
  std::string s(raw.begin(), raw.end());
  if (s.find('\0') == std::string::npos && validUtf8(s)) return s;
  s = s.substr(0, s.find('\0'));
  for (char& c : s)
    if (static_cast<unsigned char>(c) >= 0x80) c = ' ';
  auto space = [](char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r';
  };
  while (!s.empty() && space(s.back())) s.pop_back();
  std::size_t first = 0;
  while (first < s.size() && space(s[first])) ++first;
  return s.substr(first);
}

}  // namespace pitwall::testing
