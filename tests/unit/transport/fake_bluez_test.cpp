// The fake org.bluez, seen through raw sdbus-c++ proxies the way a client sees real BlueZ 5.66.
// One private bus per test case; everything runs on one real-clock loop, awaited with deadlines.
#include "tests/fake_bluez/fake_bluez.hpp"

#include <doctest/doctest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <functional>
#include <map>
#include <memory>

#include <sdbus-c++/sdbus-c++.h>

#include "engine/protocol/anki/advertisement.hpp"
#include "engine/transport/bluez_api.hpp"
#include "tests/support/private_bus.hpp"
#include "tests/support/run_until.hpp"

using namespace pitwall;
using namespace std::chrono_literals;
using testing::FakeBluez;

namespace {

namespace api = ble::api;

using Bytes = std::vector<std::uint8_t>;
using Dict = std::map<std::string, sdbus::Variant>;
using Interfaces = std::map<std::string, Dict>;
using Objects = std::map<sdbus::ObjectPath, Interfaces>;

constexpr const char* kCar = "E0:00:00:00:00:01";
const std::string kHci0 = "/org/bluez/hci0";
const std::string kDev = kHci0 + "/dev_E0_00_00_00_00_01";
const std::string kService = kDev + "/service000a";
const std::string kReadChar = kService + "/char000b";
const std::string kWriteChar = kService + "/char000d";

const Bytes kPing = {0x01, 0x16};
const Bytes kPingResponse = {0x01, 0x17};

FakeBluez::Options withCars(int adapters, int cars) {
  FakeBluez::Options o;
  o.adapters = adapters;
  o.cars = cars;
  return o;
}

Dict command() {
  return {{"type", sdbus::Variant(std::string("command"))}};
}

// A signal from org.bluez, as the client saw it.
struct Seen {
  std::string member;  // InterfacesAdded, InterfacesRemoved, PropertiesChanged
  std::string path;
  std::string iface;                 // PropertiesChanged
  Dict changed;                      // PropertiesChanged
  Interfaces added;                  // InterfacesAdded
  std::vector<std::string> removed;  // InterfacesRemoved
  TimePoint at{};
};

struct Reply {
  bool done = false;
  std::string error, message;
  std::optional<sdbus::MethodReply> reply;  // (1.2.0 crashes copying an empty MethodReply)
  bool ok() const { return done && error.empty(); }
};

// A private bus, the fake on its own connection, and a client connection with its pump.
class Rig {
 public:
  explicit Rig(FakeBluez::Options options = {})
      : server_(sdbus::createSystemBusConnection()),
        fake(loop, *server_, std::move(options)),
        client_(sdbus::createSystemBusConnection()),
        pump_(loop, *client_) {
    // sd-bus matches senders by unique name locally: use the fake's.
    watch_ = client_->addMatch("type='signal',sender='" + server_->getUniqueName() + "'",
                               [this](sdbus::Message& m) { record(m); });
    pump_.kick();
  }

  bool waitFor(const std::function<bool()>& done, Duration limit = 5s) {
    return testing::runUntil(loop, done, limit);
  }
  void runFor(Duration d) { testing::runFor(loop, d); }

  template <class... Args>
  Reply call(const std::string& path, const std::string& iface, const std::string& method,
             const Args&... args) {
    auto& p = proxy(path);
    auto m = p.createMethodCall(iface, method);
    ((void)(m << args), ...);
    auto r = std::make_shared<Reply>();
    p.callMethod(
        m,
        [r](sdbus::MethodReply& reply, const sdbus::Error* e) {
          if (e) {
            r->error = e->getName();
            r->message = e->getMessage();
          } else {
            r->reply = reply;
          }
          r->done = true;
        },
        10s);
    pump_.kick();
    REQUIRE(waitFor([&] { return r->done; }));
    return *r;
  }

  void ok(const std::string& path, const std::string& iface, const std::string& method) {
    auto r = call(path, iface, method);
    REQUIRE_MESSAGE(r.ok(), method << ": " << r.error << ": " << r.message);
  }

  sdbus::Variant get(const std::string& path, const std::string& iface, const std::string& prop) {
    auto r = call(path, api::kProperties, "Get", iface, prop);
    REQUIRE_MESSAGE(r.ok(), "Get " << prop << ": " << r.error << ": " << r.message);
    sdbus::Variant v;
    *r.reply >> v;
    return v;
  }

  Objects managedObjects() {
    auto r = call("/", api::kObjectManager, "GetManagedObjects");
    REQUIRE(r.ok());
    Objects objects;
    *r.reply >> objects;
    return objects;
  }

  // The signals seen so far that match.
  std::vector<const Seen*> seen(const std::string& member, const std::string& path) const {
    std::vector<const Seen*> out;
    for (const auto& s : signals)
      if (s.member == member && s.path == path) out.push_back(&s);
    return out;
  }
  const Seen* added(const std::string& path) const {
    auto s = seen("InterfacesAdded", path);
    return s.empty() ? nullptr : s.back();
  }
  bool removed(const std::string& path, const std::string& iface) const {
    for (const Seen* s : seen("InterfacesRemoved", path))
      if (std::count(s->removed.begin(), s->removed.end(), iface)) return true;
    return false;
  }
  // The last value a PropertiesChanged signal gave `prop` of `path`, if any.
  std::optional<sdbus::Variant> changed(const std::string& path, const std::string& prop) const {
    std::optional<sdbus::Variant> last;
    for (const Seen* s : seen("PropertiesChanged", path))
      if (auto it = s->changed.find(prop); it != s->changed.end()) last = it->second;
    return last;
  }
  bool changedTo(const std::string& path, const std::string& prop, bool value) const {
    auto v = changed(path, prop);
    return v && v->get<bool>() == value;
  }

  // StartDiscovery on hci0 and wait for the first car.
  void discover() {
    ok(kHci0, api::kAdapter, "StartDiscovery");
    REQUIRE(waitFor([&] { return added(kDev) != nullptr; }));
  }
  // Connect to the first car and wait until its services are resolved.
  void connect() {
    ok(kDev, api::kDevice, "Connect");
    REQUIRE(waitFor([&] { return changedTo(kDev, "ServicesResolved", true); }));
  }

  testing::PrivateBus bus;
  Loop loop{ClockKind::Real};

 private:
  std::unique_ptr<sdbus::IConnection> server_;

 public:
  FakeBluez fake;
  std::vector<Seen> signals;

 private:
  sdbus::IProxy& proxy(const std::string& path) {
    auto& p = proxies_[path];
    if (!p) p = sdbus::createProxy(*client_, "org.bluez", path);
    return *p;
  }

  void record(sdbus::Message& m) {
    Seen s;
    s.member = m.getMemberName();
    s.at = loop.now();
    if (s.member == "InterfacesAdded") {
      sdbus::ObjectPath path;
      m >> path >> s.added;
      s.path = path;
    } else if (s.member == "InterfacesRemoved") {
      sdbus::ObjectPath path;
      m >> path >> s.removed;
      s.path = path;
    } else if (s.member == "PropertiesChanged") {
      std::vector<std::string> invalidated;
      m >> s.iface >> s.changed >> invalidated;
      s.path = m.getPath();
    } else {
      return;
    }
    signals.push_back(std::move(s));
  }

  std::unique_ptr<sdbus::IConnection> client_;
  DbusPump pump_;
  sdbus::Slot watch_;
  std::map<std::string, std::unique_ptr<sdbus::IProxy>> proxies_;
};

// Reads one datagram from a non-blocking socket; empty when none is waiting.
Bytes readDatagram(int fd) {
  std::uint8_t buf[64];
  ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT);
  return n > 0 ? Bytes(buf, buf + n) : Bytes{};
}

}  // namespace

TEST_CASE("fake bluez: the object manager shows the adapters, and no device before discovery") {
  Rig rig(withCars(2, 3));
  Objects objects = rig.managedObjects();
  for (const std::string path : {"/org/bluez/hci0", "/org/bluez/hci1"}) {
    CAPTURE(path);
    REQUIRE(objects.count(sdbus::ObjectPath(path)));
    const Dict& adapter = objects[sdbus::ObjectPath(path)].at(api::kAdapter);
    CHECK(adapter.at("Powered").get<bool>());
    CHECK_FALSE(adapter.at("Discovering").get<bool>());
    CHECK(adapter.at("AddressType").get<std::string>() == "public");
    CHECK(adapter.at("Address").get<std::string>().size() == 17);
  }
  for (const auto& [path, interfaces] : objects) CHECK_FALSE(interfaces.count(api::kDevice));
  CHECK(rig.fake.adapterPath(1) == "/org/bluez/hci1");
  CHECK(rig.fake.devicePath("E0:00:00:00:00:02") == "/org/bluez/hci1/dev_E0_00_00_00_00_02");
}

TEST_CASE("fake bluez: StartDiscovery brings the cars of that adapter with Anki advertising data") {
  Rig rig(withCars(2, 3));  // cars 1 and 3 on hci0, car 2 on hci1
  Dict filter = {
      {"UUIDs", sdbus::Variant(std::vector<std::string>{"BE15BEEF-6186-407E-8381-0BD89C4D8DF4"})},
      {"Transport", sdbus::Variant(std::string("le"))}};
  REQUIRE(rig.call(kHci0, api::kAdapter, "SetDiscoveryFilter", filter).ok());
  auto start = rig.loop.now();
  rig.discover();
  CHECK(rig.loop.now() - start >= 10ms);  // BlueZ reports what the radio hears, not at once
  CHECK(rig.changedTo(kHci0, "Discovering", true));

  const Dict& device = rig.added(kDev)->added.at(api::kDevice);
  sim::SimCar& car = rig.fake.car(kCar);
  CHECK(device.at("Address").get<std::string>() == kCar);
  CHECK(device.at("AddressType").get<std::string>() == "random");
  CHECK(device.at("Adapter").get<sdbus::ObjectPath>() == kHci0);
  CHECK(device.at("UUIDs").get<std::vector<std::string>>() ==
        std::vector<std::string>{std::string(anki::kServiceUuid)});
  CHECK_FALSE(device.at("Connected").get<bool>());
  CHECK_FALSE(device.at("Paired").get<bool>());
  auto rssi = device.at("RSSI").get<std::int16_t>();
  CHECK((rssi < -20 && rssi > -100));

  // ManufacturerData: key 0xEFBE (BE EF little-endian) → the 6 bytes after it.
  auto md = device.at("ManufacturerData").get<std::map<std::uint16_t, sdbus::Variant>>();
  REQUIRE(md.size() == 1);
  REQUIRE(md.count(anki::kManufacturerKey));
  auto value = md.at(anki::kManufacturerKey).get<Bytes>();
  auto raw = car.manufacturerData();
  CHECK(value == Bytes(raw.begin() + 2, raw.end()));
  auto parsed = anki::parseManufacturerData(anki::kManufacturerKey, value);
  REQUIRE(parsed);
  CHECK(parsed->model_id == car.spec().model_id);
  CHECK(parsed->identifier == car.identifier());

  // AdvertisingData[0x09] is the raw local name; Name is what BlueZ makes of it: the state byte
  // of a car that is not fully charged is 0, so the name is empty and there is no Name at all.
  auto ad = device.at("AdvertisingData").get<std::map<std::uint8_t, sdbus::Variant>>();
  REQUIRE(ad.count(0x09));
  CHECK(ad.at(0x09).get<Bytes>() == car.localName());
  CHECK_FALSE(device.count("Name"));
  CHECK(device.at("Alias").get<std::string>() == "E0-00-00-00-00-01");

  // The other car of hci0 comes too; hci1 does not discover.
  CHECK(rig.waitFor([&] { return rig.added(kHci0 + "/dev_E0_00_00_00_00_03") != nullptr; }));
  CHECK(rig.added("/org/bluez/hci1/dev_E0_00_00_00_00_02") == nullptr);
  CHECK(rig.managedObjects().count(sdbus::ObjectPath(kDev)));
}

TEST_CASE("fake bluez: discovery answers with BlueZ's errors and respects the UUID filter") {
  Rig rig;
  rig.ok(kHci0, api::kAdapter, "StartDiscovery");
  auto again = rig.call(kHci0, api::kAdapter, "StartDiscovery");
  CHECK(again.error == "org.bluez.Error.InProgress");
  CHECK(again.message == "Operation already in progress");
  rig.ok(kHci0, api::kAdapter, "StopDiscovery");
  auto stop = rig.call(kHci0, api::kAdapter, "StopDiscovery");
  CHECK(stop.error == "org.bluez.Error.Failed");
  CHECK(stop.message == "No discovery started");
  CHECK(rig.changedTo(kHci0, "Discovering", false));

  auto bogus = rig.call(kHci0, api::kAdapter, "SetDiscoveryFilter",
                        Dict{{"Colour", sdbus::Variant(std::string("red"))}});
  CHECK(bogus.error == "org.bluez.Error.InvalidArguments");
  auto filters = rig.call(kHci0, api::kAdapter, "GetDiscoveryFilters");
  std::vector<std::string> names;
  *filters.reply >> names;
  CHECK(std::count(names.begin(), names.end(), "UUIDs") == 1);

  // Heart-rate devices only: the car is not reported.
  Dict heartRate = {{"UUIDs", sdbus::Variant(std::vector<std::string>{"180d"})}};
  REQUIRE(rig.call(kHci0, api::kAdapter, "SetDiscoveryFilter", heartRate).ok());
  rig.ok(kHci0, api::kAdapter, "StartDiscovery");
  rig.runFor(100ms);
  CHECK(rig.added(kDev) == nullptr);
  CHECK_FALSE(rig.fake.exported(kCar));
}

TEST_CASE("fake bluez: discovery ends when the client that started it leaves the bus") {
  Rig rig;
  {
    auto other = sdbus::createSystemBusConnection();
    DbusPump otherPump(rig.loop, *other);
    auto adapter = sdbus::createProxy(*other, "org.bluez", kHci0);
    bool started = false;
    adapter->callMethodAsync("StartDiscovery")
        .onInterface(api::kAdapter)
        .uponReplyInvoke([&](const sdbus::Error* e) { started = e == nullptr; });
    otherPump.kick();
    REQUIRE(rig.waitFor([&] { return started; }));
    REQUIRE(rig.waitFor([&] { return rig.added(kDev) != nullptr; }));
  }  // the other client's connection closes
  CHECK(rig.waitFor([&] { return rig.changedTo(kHci0, "Discovering", false); }));
  CHECK_FALSE(rig.get(kHci0, api::kAdapter, "Discovering").get<bool>());
  CHECK(rig.fake.exported(kCar));  // BlueZ keeps the devices it found
}

TEST_CASE("fake bluez: Connect makes Connected, the GATT objects, then ServicesResolved") {
  Rig rig;
  rig.discover();
  auto start = rig.loop.now();
  rig.ok(kDev, api::kDevice, "Connect");
  CHECK(rig.loop.now() - start >= 20ms);
  CHECK(rig.changedTo(kDev, "Connected", true));
  REQUIRE(rig.added(kService));
  REQUIRE(rig.added(kReadChar));
  REQUIRE(rig.added(kWriteChar));
  CHECK_FALSE(rig.changed(kDev, "ServicesResolved"));  // not yet
  REQUIRE(rig.waitFor([&] { return rig.changedTo(kDev, "ServicesResolved", true); }));

  const Dict& service = rig.added(kService)->added.at(api::kGattService);
  CHECK(service.at("UUID").get<std::string>() == anki::kServiceUuid);
  CHECK(service.at("Primary").get<bool>());
  CHECK(service.at("Device").get<sdbus::ObjectPath>() == kDev);

  const Dict& read = rig.added(kReadChar)->added.at(api::kGattCharacteristic);
  CHECK(read.at("UUID").get<std::string>() == anki::kReadCharUuid);
  CHECK(read.at("Service").get<sdbus::ObjectPath>() == kService);
  CHECK(read.at("Flags").get<std::vector<std::string>>() ==
        std::vector<std::string>{"read", "notify"});
  CHECK_FALSE(read.at("Notifying").get<bool>());
  CHECK_FALSE(read.at("NotifyAcquired").get<bool>());
  CHECK(read.at("MTU").get<std::uint16_t>() == 23);

  const Dict& write = rig.added(kWriteChar)->added.at(api::kGattCharacteristic);
  CHECK(write.at("UUID").get<std::string>() == anki::kWriteCharUuid);
  CHECK(write.at("Flags").get<std::vector<std::string>>() ==
        std::vector<std::string>{"read", "write-without-response", "write"});
  CHECK_FALSE(write.at("WriteAcquired").get<bool>());

  rig.ok(kDev, api::kDevice, "Connect");  // already connected: BlueZ says yes at once
  CHECK(rig.fake.counters(kCar).connectCalls == 2);
  CHECK(rig.fake.counters(kCar).connects == 1);
  CHECK(rig.fake.car(kCar).truth().connected);
}

TEST_CASE("fake bluez: StartNotify and WriteValue carry a ping and its response") {
  Rig rig;
  rig.discover();
  rig.connect();
  rig.ok(kReadChar, api::kGattCharacteristic, "StartNotify");
  CHECK(rig.changedTo(kReadChar, "Notifying", true));
  REQUIRE(rig.call(kWriteChar, api::kGattCharacteristic, "WriteValue", kPing, command()).ok());
  REQUIRE(rig.waitFor([&] {
    auto v = rig.changed(kReadChar, "Value");
    return v && v->get<Bytes>() == kPingResponse;
  }));
  auto read = rig.call(kReadChar, api::kGattCharacteristic, "ReadValue", Dict{});
  Bytes value;
  *read.reply >> value;
  CHECK(value == kPingResponse);
  CHECK(rig.fake.counters(kCar).framesToCar == 1);
  CHECK(rig.fake.counters(kCar).framesToClient >= 1);

  // A write request (no type) goes through too; a command to the read characteristic does not.
  REQUIRE(rig.call(kWriteChar, api::kGattCharacteristic, "WriteValue", kPing, Dict{}).ok());
  CHECK(rig.call(kReadChar, api::kGattCharacteristic, "WriteValue", kPing, command()).error ==
        "org.bluez.Error.NotSupported");

  rig.ok(kReadChar, api::kGattCharacteristic, "StopNotify");
  CHECK(rig.changedTo(kReadChar, "Notifying", false));
  auto again = rig.call(kReadChar, api::kGattCharacteristic, "StopNotify");
  CHECK(again.error == "org.bluez.Error.Failed");
  CHECK(again.message == "No notify session started");
}

TEST_CASE("fake bluez: AcquireNotify and AcquireWrite carry frames as datagrams") {
  Rig rig;
  rig.discover();
  rig.connect();
  auto n = rig.call(kReadChar, api::kGattCharacteristic, "AcquireNotify", Dict{});
  REQUIRE_MESSAGE(n.ok(), n.error << ": " << n.message);
  auto w = rig.call(kWriteChar, api::kGattCharacteristic, "AcquireWrite", Dict{});
  REQUIRE_MESSAGE(w.ok(), w.error << ": " << w.message);
  sdbus::UnixFd notifyFd, writeFd;
  std::uint16_t notifyMtu = 0, writeMtu = 0;
  *n.reply >> notifyFd >> notifyMtu;
  *w.reply >> writeFd >> writeMtu;
  n.reply.reset();  // a received message holds its own copy of the descriptor
  w.reply.reset();
  CHECK(notifyMtu == 23);
  CHECK(writeMtu == 23);
  CHECK(rig.get(kReadChar, api::kGattCharacteristic, "NotifyAcquired").get<bool>());
  CHECK(rig.get(kWriteChar, api::kGattCharacteristic, "WriteAcquired").get<bool>());

  REQUIRE(::send(writeFd.get(), kPing.data(), kPing.size(), MSG_NOSIGNAL) == 2);
  Bytes got;
  REQUIRE(rig.waitFor([&] {
    got = readDatagram(notifyFd.get());
    return got == kPingResponse;
  }));
  CHECK(rig.fake.counters(kCar).framesToCar == 1);

  // While acquired, the D-Bus ways are closed (gatt-client.c).
  auto write = rig.call(kWriteChar, api::kGattCharacteristic, "WriteValue", kPing, command());
  CHECK(write.error == "org.bluez.Error.NotPermitted");
  CHECK(write.message == "Write acquired");
  auto start = rig.call(kReadChar, api::kGattCharacteristic, "StartNotify");
  CHECK(start.error == "org.bluez.Error.NotPermitted");
  CHECK(start.message == "Notify acquired");

  // The client closes its ends: the fake lets go, and car frames are no longer delivered.
  notifyFd.reset();
  REQUIRE(rig.waitFor([&] { return rig.changedTo(kReadChar, "NotifyAcquired", false); }));
  auto dropped = rig.fake.counters(kCar).framesDropped;
  REQUIRE(::send(writeFd.get(), kPing.data(), kPing.size(), MSG_NOSIGNAL) == 2);
  CHECK(rig.waitFor([&] { return rig.fake.counters(kCar).framesDropped > dropped; }));
  writeFd.reset();
  CHECK(rig.waitFor([&] { return rig.changedTo(kWriteChar, "WriteAcquired", false); }));
}

TEST_CASE("fake bluez: a set-speed write makes the simulated car drive") {
  Rig rig;
  rig.discover();
  rig.connect();
  Bytes sdkMode = {0x03, 0x90, 0x01, 0x01};
  Bytes setSpeed = {0x06, 0x24, 0xe8, 0x03, 0xa8, 0x61, 0x00};  // 1000 mm/s, 25000 mm/s²
  REQUIRE(rig.call(kWriteChar, api::kGattCharacteristic, "WriteValue", sdkMode, Dict{}).ok());
  REQUIRE(rig.call(kWriteChar, api::kGattCharacteristic, "WriteValue", setSpeed, command()).ok());
  sim::SimCar& car = rig.fake.car(kCar);
  CHECK(rig.waitFor([&] { return car.truth().speed_mm_s > 0; }, 2s));
  CHECK(car.truth().target_speed_mm_s == doctest::Approx(1000));

  rig.ok(kDev, api::kDevice, "Disconnect");  // the controller goes away: the car stops
  CHECK_FALSE(car.truth().connected);
  CHECK(car.truth().target_speed_mm_s == 0);
}

TEST_CASE("fake bluez: a refused car's Connect fails like an aborted LE connection") {
  Rig rig;
  rig.fake.refuse(kCar);
  rig.discover();
  auto r = rig.call(kDev, api::kDevice, "Connect");
  CHECK(r.error == "org.bluez.Error.Failed");
  CHECK(r.message == "le-connection-abort-by-local");
  CHECK_FALSE(rig.get(kDev, api::kDevice, "Connected").get<bool>());
  CHECK(rig.added(kService) == nullptr);
  CHECK(rig.fake.counters(kCar).connectCalls == 1);
  CHECK(rig.fake.counters(kCar).connects == 0);

  rig.fake.refuse(kCar, false);
  rig.connect();
}

TEST_CASE("fake bluez: a dropped link takes the GATT objects; the device stays and reconnects") {
  Rig rig;
  rig.discover();
  rig.connect();
  rig.fake.drop(kCar);
  REQUIRE(rig.waitFor([&] { return rig.changedTo(kDev, "Connected", false); }));
  CHECK(rig.changedTo(kDev, "ServicesResolved", false));
  CHECK(rig.waitFor([&] {
    return rig.removed(kReadChar, api::kGattCharacteristic) &&
           rig.removed(kWriteChar, api::kGattCharacteristic) &&
           rig.removed(kService, api::kGattService);
  }));
  CHECK_FALSE(rig.removed(kDev, api::kDevice));
  CHECK(rig.managedObjects().count(sdbus::ObjectPath(kDev)));
  CHECK_FALSE(rig.fake.car(kCar).truth().connected);

  rig.signals.clear();
  rig.connect();
  CHECK(rig.added(kReadChar));
  CHECK(rig.fake.counters(kCar).connects == 2);
  CHECK(rig.fake.counters(kCar).disconnects == 1);
}

TEST_CASE("fake bluez: a vanished car is removed and does not come back") {
  Rig rig;
  rig.discover();  // and it keeps discovering
  rig.connect();
  rig.fake.vanish(kCar);
  REQUIRE(rig.waitFor([&] { return rig.removed(kDev, api::kDevice); }));
  CHECK(rig.changedTo(kDev, "Connected", false));
  CHECK(rig.removed(kReadChar, api::kGattCharacteristic));
  std::size_t sightings = rig.seen("InterfacesAdded", kDev).size();
  rig.runFor(250ms);  // longer than the advertising period
  CHECK(rig.seen("InterfacesAdded", kDev).size() == sightings);
  CHECK_FALSE(rig.managedObjects().count(sdbus::ObjectPath(kDev)));
  CHECK(rig.call(kDev, api::kDevice, "Connect").error ==
        "org.freedesktop.DBus.Error.UnknownObject");
}

TEST_CASE("fake bluez: a car that hangs up ends the link") {
  Rig rig;
  rig.discover();
  rig.connect();
  REQUIRE(rig.call(kWriteChar, api::kGattCharacteristic, "WriteValue", Bytes{0x01, 0x0d}, command())
              .ok());
  CHECK(rig.waitFor([&] { return rig.changedTo(kDev, "Connected", false); }));
  CHECK(rig.waitFor([&] { return rig.removed(kService, api::kGattService); }));
  CHECK_FALSE(rig.fake.connected(kCar));
}

TEST_CASE("fake bluez: RemoveDevice forgets a device until it is heard again") {
  Rig rig;
  rig.discover();
  auto notConnected = rig.call(kDev, api::kDevice, "Disconnect");
  CHECK(notConnected.error == "org.bluez.Error.NotConnected");
  REQUIRE(rig.call(kHci0, api::kAdapter, "RemoveDevice", sdbus::ObjectPath(kDev)).ok());
  CHECK(rig.removed(kDev, api::kDevice));
  CHECK(rig.call(kHci0, api::kAdapter, "RemoveDevice", sdbus::ObjectPath(kDev)).error ==
        "org.bluez.Error.DoesNotExist");
  // Discovery still runs: the next advertisement brings the car back.
  CHECK(rig.waitFor([&] { return rig.seen("InterfacesAdded", kDev).size() == 2; }));
}

TEST_CASE("fake bluez: without acquire, AcquireNotify and AcquireWrite are not supported") {
  FakeBluez::Options options;
  options.noAcquire = true;
  Rig rig(options);
  rig.discover();
  rig.connect();
  CHECK(rig.call(kReadChar, api::kGattCharacteristic, "AcquireNotify", Dict{}).error ==
        "org.bluez.Error.NotSupported");
  CHECK(rig.call(kWriteChar, api::kGattCharacteristic, "AcquireWrite", Dict{}).error ==
        "org.bluez.Error.NotSupported");
  rig.ok(kReadChar, api::kGattCharacteristic, "StartNotify");  // the fallback works
  REQUIRE(rig.call(kWriteChar, api::kGattCharacteristic, "WriteValue", kPing, command()).ok());
  CHECK(rig.waitFor([&] {
    auto v = rig.changed(kReadChar, "Value");
    return v && v->get<Bytes>() == kPingResponse;
  }));
}

TEST_CASE("fake bluez: scheduled faults count from the first connection") {
  Rig rig;
  rig.fake.schedule(FakeBluez::Fault::Garbage, kCar, 150ms);
  rig.fake.schedule(FakeBluez::Fault::Drop, kCar, 250ms);
  rig.discover();
  rig.ok(kDev, api::kDevice, "Connect");
  auto connectedAt = rig.loop.now();
  rig.ok(kReadChar, api::kGattCharacteristic, "StartNotify");
  std::vector<Bytes> values;
  REQUIRE(rig.waitFor([&] { return rig.changedTo(kDev, "Connected", false); }));
  CHECK(rig.loop.now() - connectedAt >= 200ms);
  for (const Seen* s : rig.seen("PropertiesChanged", kReadChar))
    if (auto it = s->changed.find("Value"); it != s->changed.end())
      values.push_back(it->second.get<Bytes>());
  CHECK(values == FakeBluez::garbageFrames());
}

TEST_CASE("fake bluez: Name is what BlueZ 5.66 makes of a local name") {
  // Anki: state bits, version (LE), 5 reserved NULs, user name.
  Bytes full = {0x10, 0x70, 0x2b, 0, 0, 0, 0, 0, 'g', 's', 0};
  CHECK(FakeBluez::bluezName(full) == "\x10p+");
  Bytes notFull = {0x00, 0x70, 0x2b, 0, 0, 0, 0, 0, 'g', 's', 0};
  CHECK(FakeBluez::bluezName(notFull).empty());
  std::string zoe = "Zo\xc3\xab";  // valid UTF-8, no NUL: taken whole
  CHECK(FakeBluez::bluezName(Bytes(zoe.begin(), zoe.end())) == zoe);
  Bytes odd = {' ', 'a', 0xff, 'b', ' ', 0, 'c'};  // non-ASCII → space, then trimmed
  CHECK(FakeBluez::bluezName(odd) == "a b");
}

TEST_CASE("fake bluez: it takes a connection that owns org.bluez, and refuses a second BlueZ") {
  testing::PrivateBus bus;
  Loop loop(ClockKind::Real);
  auto owner = sdbus::createSystemBusConnection("org.bluez");
  FakeBluez fake(loop, *owner);
  auto other = sdbus::createSystemBusConnection();
  CHECK_THROWS_AS(FakeBluez(loop, *other), sdbus::Error);
}
