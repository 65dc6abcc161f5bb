#include "engine/transport/ble_peripheral.hpp"

#include <chrono>
#include <cstdio>
#include <map>

#include <sdbus-c++/sdbus-c++.h>

#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/core/printable.hpp"
#include "engine/transport/bluez_api.hpp"

namespace pitwall {
namespace {

namespace api = ble::api;

constexpr const char* kComponent = "ble";
// BlueZ answers in milliseconds; a call still pending after this means bluetoothd is stuck.
constexpr std::chrono::seconds kCallTimeout{10};

using Options = std::map<std::string, sdbus::Variant>;

// How the local name goes into the advertisement, tried in this order until BlueZ accepts one.
// An Anki car's local name is binary (state byte, version, reserved NULs, then the user name), so
// the raw bytes are tried first as AD type 0x09 through the experimental `Data` property
// (bluetoothd -E). BlueZ 5.66 refuses that: `Data` may not carry the types BlueZ manages itself,
// names included (src/shared/ad.c, type_reject_list). The service UUID (18 bytes) and the
// manufacturer data (10) already fill the 31-byte advertising data with the flags (3), and 5.66
// has no ScanResponse* properties; what it does put in the scan response is `LocalName`, a
// string (UTF-8, no NUL): emulate-car gives the name's layout with control characters for the
// zeros (anki::localNameText), or the plain user name (anki-overdrive.md "Advertisement").
enum class NameForm { RawData, LocalName, None };

std::string formDescription(NameForm form, const PeripheralSpec& spec) {
  switch (form) {
    case NameForm::RawData:
      return "Data 0x09 (" + std::to_string(spec.localName.size()) + " raw bytes)";
    case NameForm::LocalName:
      return "LocalName \"" + printable(spec.localNameText) + "\" (scan response)";
    case NameForm::None:
      return "no local name";
  }
  return "?";
}

bool isNoBluez(const sdbus::Error& e) {
  return e.getName() == "org.freedesktop.DBus.Error.ServiceUnknown" ||
         e.getName() == "org.freedesktop.DBus.Error.NameHasNoOwner";
}

bool isNoObject(const sdbus::Error& e) {
  return e.getName() == "org.freedesktop.DBus.Error.UnknownObject" ||
         e.getName() == "org.freedesktop.DBus.Error.UnknownMethod" ||
         e.getName() == "org.freedesktop.DBus.Error.UnknownInterface" ||
         e.getName() == "org.freedesktop.DBus.Error.InvalidArgs";
}

std::string errorText(const sdbus::Error& e) {
  return e.getName() + (e.getMessage().empty() ? "" : ": " + e.getMessage());
}

// "/org/bluez/hci0/dev_00_AA_01_01_00_01" is a device of adapter hci0; its services are not.
bool isDeviceOf(const std::string& path, const std::string& adapterPath) {
  const std::string prefix = adapterPath + "/dev_";
  return path.compare(0, prefix.size(), prefix) == 0 &&
         path.find('/', prefix.size()) == std::string::npos;
}

}  // namespace

// Replies and signals never outlive the peripheral: its proxies, objects and match slots are
// members here, and sdbus-c++ cancels their pending calls and handlers when they go.
struct BlePeripheral::State {
  BlePeripheral& self;
  DbusPump& pump;
  sdbus::IConnection& conn;
  PeripheralSpec spec;
  std::string adapterPath, appPath, servicePath, notifyPath, writePath, advPath;

  std::unique_ptr<sdbus::IObject> app, service, notifyChar, writeChar, advert;
  std::unique_ptr<sdbus::IProxy> adapter, device;
  sdbus::Slot propertiesMatch, addedMatch, removedMatch, ownerMatch;
  Loop::TimerId againTimer = 0;  // registering again after bluetoothd came back
  int againTries = 0;
  int bluezLives = 0;  // bluetoothd went away this many times: an answer from before is no news

  std::vector<std::uint8_t> value;  // last notified value: ReadValue and the Value property
  bool notifying = false;
  bool linkUp = false;
  std::string peer;  // the central's Device1 path on our adapter, once known

  NameForm form = NameForm::RawData;
  std::string advertisedName;
  bool appRegistered = false, advertising = false, readvertising = false;

  State(BlePeripheral& s, DbusPump& p, PeripheralSpec sp)
      : self(s), pump(p), conn(p.connection()), spec(std::move(sp)) {
    adapterPath = "/org/bluez/" + spec.adapter;
    appPath = "/org/pitwall/peripheral/" + spec.adapter;
    servicePath = appPath + "/service0";
    notifyPath = servicePath + "/char0";
    writePath = servicePath + "/char1";
    advPath = "/org/pitwall/advertisement/" + spec.adapter;
  }
  ~State() {
    if (againTimer) pump.loop().cancel(againTimer);
  }

  void exportObjects() {
    // The application root is an ObjectManager: BlueZ reads the whole tree with
    // GetManagedObjects when RegisterApplication is called (gatt-api "GattManager1").
    app = sdbus::createObject(conn, appPath);
    app->addObjectManager();
    app->finishRegistration();

    service = sdbus::createObject(conn, servicePath);
    service->registerProperty("UUID").onInterface(api::kGattService).withGetter([this] {
      return spec.serviceUuid;
    });
    service->registerProperty("Primary").onInterface(api::kGattService).withGetter([] {
      return true;
    });
    service->finishRegistration();

    notifyChar = sdbus::createObject(conn, notifyPath);
    notifyChar->registerProperty("UUID").onInterface(api::kGattCharacteristic).withGetter([this] {
      return spec.notifyCharUuid;
    });
    notifyChar->registerProperty("Service")
        .onInterface(api::kGattCharacteristic)
        .withGetter([this] { return sdbus::ObjectPath(servicePath); });
    notifyChar->registerProperty("Flags").onInterface(api::kGattCharacteristic).withGetter([] {
      return std::vector<std::string>{"read", "notify"};
    });
    notifyChar->registerProperty("Value").onInterface(api::kGattCharacteristic).withGetter([this] {
      return value;
    });
    notifyChar->registerProperty("Notifying")
        .onInterface(api::kGattCharacteristic)
        .withGetter([this] { return notifying; });
    notifyChar->registerMethod("ReadValue")
        .onInterface(api::kGattCharacteristic)
        .implementedAs([this](const Options& options) {
          std::size_t offset = 0;
          if (auto it = options.find("offset"); it != options.end())
            offset = it->second.get<std::uint16_t>();
          if (offset > value.size())
            throw sdbus::Error("org.bluez.Error.InvalidOffset", "offset past the value");
          return std::vector<std::uint8_t>(value.begin() + static_cast<long>(offset), value.end());
        });
    notifyChar->registerMethod("StartNotify")
        .onInterface(api::kGattCharacteristic)
        .implementedAs([this] {
          setNotifying(true);
          up(peer);
        });
    notifyChar->registerMethod("StopNotify")
        .onInterface(api::kGattCharacteristic)
        .implementedAs([this] {
          setNotifying(false);
          down("the central unsubscribed");
        });
    notifyChar->finishRegistration();

    writeChar = sdbus::createObject(conn, writePath);
    writeChar->registerProperty("UUID").onInterface(api::kGattCharacteristic).withGetter([this] {
      return spec.writeCharUuid;
    });
    writeChar->registerProperty("Service").onInterface(api::kGattCharacteristic).withGetter([this] {
      return sdbus::ObjectPath(servicePath);
    });
    writeChar->registerProperty("Flags").onInterface(api::kGattCharacteristic).withGetter([] {
      return std::vector<std::string>{"write", "write-without-response"};
    });
    writeChar->registerMethod("WriteValue")
        .onInterface(api::kGattCharacteristic)
        .implementedAs([this](const std::vector<std::uint8_t>& bytes, const Options& options) {
          // options: device (o), link (s), mtu (q), offset (q), type (s) — gatt-api.
          std::string device;
          if (auto it = options.find("device"); it != options.end())
            device = it->second.get<sdbus::ObjectPath>();
          if (peer.empty()) peer = device;
          log::debug(kComponent, "write " + toHex(bytes));
          up(device);  // a central may write before it subscribes
          if (self.onWrite) self.onWrite(bytes);
        });
    writeChar->finishRegistration();

    advert = sdbus::createObject(conn, advPath);
    advert->registerProperty("Type").onInterface(api::kAdvertisement).withGetter([] {
      return std::string("peripheral");
    });
    advert->registerProperty("ServiceUUIDs").onInterface(api::kAdvertisement).withGetter([this] {
      return std::vector<std::string>{spec.serviceUuid};
    });
    advert->registerProperty("ManufacturerData")
        .onInterface(api::kAdvertisement)
        .withGetter([this] {
          return std::map<std::uint16_t, sdbus::Variant>{
              {spec.manufacturerKey, sdbus::Variant(spec.manufacturerData)}};
        });
    advert->registerProperty("Discoverable").onInterface(api::kAdvertisement).withGetter([] {
      return true;
    });
    // Both name properties always exist; the form picks which one carries the name (an empty
    // LocalName is "no name" to BlueZ, an empty Data dictionary adds nothing).
    advert->registerProperty("Data").onInterface(api::kAdvertisement).withGetter([this] {
      std::map<std::uint8_t, sdbus::Variant> data;
      if (form == NameForm::RawData) data.emplace(0x09, sdbus::Variant(spec.localName));
      return data;
    });
    advert->registerProperty("LocalName").onInterface(api::kAdvertisement).withGetter([this] {
      return form == NameForm::LocalName ? spec.localNameText : std::string();
    });
    advert->registerMethod("Release").onInterface(api::kAdvertisement).implementedAs([this] {
      log::info(kComponent, "BlueZ released the advertisement on " + spec.adapter);
      advertising = false;
    });
    advert->finishRegistration();
  }

  void watchDevices() {
    // The central's Device1 object on our adapter says when the link goes down. No sender in
    // the rules: sd-bus cannot match a well-known sender name locally; the paths are BlueZ's.
    propertiesMatch = conn.addMatch(
        "type='signal',interface='org.freedesktop.DBus.Properties',member='PropertiesChanged',"
        "path_namespace='" +
            adapterPath + "'",
        ([this](sdbus::Message& m) {
          std::string iface;
          std::map<std::string, sdbus::Variant> changed;
          m >> iface >> changed;
          if (iface != api::kDevice || !isDeviceOf(m.getPath(), adapterPath)) return;
          auto it = changed.find("Connected");
          if (it == changed.end()) return;
          if (it->second.get<bool>())
            deviceConnected(m.getPath());
          else
            deviceGone(m.getPath());
        }));
    addedMatch = conn.addMatch(
        "type='signal',interface='org.freedesktop.DBus.ObjectManager',member='InterfacesAdded',"
        "path='/'",
        ([this](sdbus::Message& m) {
          sdbus::ObjectPath path;
          std::map<std::string, std::map<std::string, sdbus::Variant>> ifaces;
          m >> path >> ifaces;
          auto device = ifaces.find(api::kDevice);
          if (device == ifaces.end() || !isDeviceOf(path, adapterPath)) return;
          auto connected = device->second.find("Connected");
          if (connected != device->second.end() && connected->second.get<bool>())
            deviceConnected(path);
        }));
    // bluetoothd restarting takes the link and both registrations with it: as a real car is
    // found again after its host's restart, the emulated one registers again when BlueZ is back
    ownerMatch = conn.addMatch(
        "type='signal',sender='org.freedesktop.DBus',path='/org/freedesktop/DBus',"
        "interface='org.freedesktop.DBus',member='NameOwnerChanged',arg0='org.bluez'",
        ([this](sdbus::Message& m) {
          std::string name, oldOwner, newOwner;
          m >> name >> oldOwner >> newOwner;
          if (name != api::kService) return;
          if (newOwner.empty())
            bluezGone();
          else
            bluezBack();
        }));
    removedMatch = conn.addMatch(
        "type='signal',interface='org.freedesktop.DBus.ObjectManager',member='InterfacesRemoved',"
        "path='/'",
        ([this](sdbus::Message& m) {
          sdbus::ObjectPath path;
          std::vector<std::string> ifaces;
          m >> path >> ifaces;
          for (const auto& i : ifaces)
            if (i == api::kDevice && isDeviceOf(path, adapterPath)) deviceGone(path);
        }));
  }

  // ---- the link ----

  void deviceConnected(const std::string& path) {
    log::debug(kComponent, "a central connected: " + path);
    if (peer.empty()) peer = path;
  }

  void deviceGone(const std::string& path) {
    if (!peer.empty() && path != peer) return;
    log::debug(kComponent, "the central disconnected: " + path);
    peer.clear();
    if (notifying) setNotifying(false);
    down("the central disconnected");
    readvertise();
  }

  void up(const std::string& device) {
    if (linkUp) return;
    linkUp = true;
    if (self.onConnected) self.onConnected(device.empty() ? std::string("a central") : device);
  }

  void down(const std::string& why) {
    if (!linkUp) return;
    linkUp = false;
    log::debug(kComponent, why);
    if (self.onDisconnected) self.onDisconnected();
  }

  // bluetoothd went away (restarted, or it died): the central's link and our registrations
  // went with it.
  void bluezGone() {
    log::warn(kComponent, "BlueZ went away (bluetoothd stopped): off the air until it is back");
    if (againTimer) pump.loop().cancel(againTimer);
    againTimer = 0;
    peer.clear();
    if (notifying) setNotifying(false);
    down("bluetoothd went away");
    appRegistered = advertising = readvertising = false;
    ++bluezLives;
  }

  // bluetoothd is back: once the adapter is there and powered (looked at every 0.5 s for 30 s),
  // the application and the advertisement are registered again.
  void bluezBack() {
    if (againTimer) pump.loop().cancel(againTimer);
    againTimer = 0;
    againTries = 0;
    registerAgain();
  }

  void registerAgain() {
    checkAdapter([this](const std::string& error) {
      if (!error.empty()) {
        if (++againTries >= 60)
          return log::error(kComponent, "BlueZ is back, but " + error + ": off the air");
        againTimer = pump.loop().after(std::chrono::milliseconds(500), [this] {
          againTimer = 0;
          registerAgain();
        });
        return;
      }
      registerApplication([this](const std::string& error) {
        if (!error.empty()) return log::error(kComponent, "BlueZ is back, but " + error);
        form = NameForm::RawData;
        registerAdvertisement([this](const std::string& error) {
          if (!error.empty()) return log::error(kComponent, "BlueZ is back, but " + error);
          log::info(kComponent, "BlueZ is back: advertising again on " + spec.adapter);
        });
      });
    });
  }

  void setNotifying(bool on) {
    notifying = on;
    notifyChar->emitPropertiesChangedSignal(api::kGattCharacteristic, {"Notifying"});
  }

  // ---- registration ----

  void checkAdapter(std::function<void(const std::string&)> done) {
    adapter = sdbus::createProxy(conn, api::kService, adapterPath);
    adapter->callMethodAsync("Get")
        .onInterface(api::kProperties)
        .withTimeout(kCallTimeout)
        .withArguments(std::string(api::kAdapter), std::string("Powered"))
        .uponReplyInvoke([this, done](const sdbus::Error* e, sdbus::Variant powered) {
          if (e && isNoBluez(*e))
            return done(
                "BlueZ is not running: nothing owns org.bluez on the system bus (start "
                "bluetoothd)");
          if (e && isNoObject(*e))
            return done("BlueZ has no adapter " + spec.adapter +
                        " (`bluetoothctl list` shows the adapters; choose one with --adapter)");
          if (e) return done("cannot read adapter " + spec.adapter + ": " + errorText(*e));
          if (!powered.get<bool>())
            return done(
                "adapter " + spec.adapter +
                " is powered off (`bluetoothctl power on`, or `btmgmt --index N power on`)");
          done("");
        });
    pump.kick();
  }

  void registerApplication(std::function<void(const std::string&)> done) {
    adapter->callMethodAsync("RegisterApplication")
        .onInterface(api::kGattManager)
        .withTimeout(kCallTimeout)
        .withArguments(sdbus::ObjectPath(appPath), Options{})
        .uponReplyInvoke([this, done](const sdbus::Error* e) {
          if (e && isNoObject(*e))
            return done("adapter " + spec.adapter + " has no GATT manager (" + errorText(*e) +
                        "): is it an LE controller?");
          if (e)
            return done("BlueZ refused the GATT application on " + spec.adapter + ": " +
                        errorText(*e));
          appRegistered = true;
          done("");
        });
    pump.kick();
  }

  // Registers the advertisement in the current form, falling back to the next one when BlueZ
  // refuses it; `done` gets "" once one was accepted.
  void registerAdvertisement(std::function<void(const std::string&)> done) {
    adapter->callMethodAsync("RegisterAdvertisement")
        .onInterface(api::kAdvertisingManager)
        .withTimeout(kCallTimeout)
        .withArguments(sdbus::ObjectPath(advPath), Options{})
        .uponReplyInvoke([this, done](const sdbus::Error* e) {
          if (!e) {
            advertising = true;
            advertisedName = formDescription(form, spec);
            return done("");
          }
          if (isNoObject(*e) && e->getName() != "org.freedesktop.DBus.Error.InvalidArgs")
            return done("adapter " + spec.adapter + " cannot advertise (" + errorText(*e) +
                        "): is it an LE controller?");
          log::debug(kComponent, "BlueZ refused the advertisement with " +
                                     formDescription(form, spec) + ": " + errorText(*e));
          if (form == NameForm::None)
            return done("BlueZ refused the advertisement on " + spec.adapter + ": " +
                        errorText(*e));
          form = form == NameForm::RawData ? NameForm::LocalName : NameForm::None;
          registerAdvertisement(done);
        });
    pump.kick();
  }

  // After a central went away: unregister and register again, so the next one finds the car
  // (whether or not the kernel resumed the advertising instance the connection stopped).
  void readvertise() {
    if (readvertising || !adapter) return;
    readvertising = true;
    adapter->callMethodAsync("UnregisterAdvertisement")
        .onInterface(api::kAdvertisingManager)
        .withTimeout(kCallTimeout)
        .withArguments(sdbus::ObjectPath(advPath))
        .uponReplyInvoke([this, lives = bluezLives](const sdbus::Error*) {
          if (lives != bluezLives) return;  // bluetoothd went away meanwhile: registered anew
          advertising = false;
          registerAdvertisement([this, lives](const std::string& error) {
            if (lives != bluezLives) return;
            readvertising = false;
            if (!error.empty())
              log::error(kComponent, "cannot advertise again: " + error);
            else
              log::debug(kComponent, "advertising again on " + spec.adapter);
          });
        });
    pump.kick();
  }
};

BlePeripheral::BlePeripheral(DbusPump& pump, PeripheralSpec spec)
    : state_(std::make_unique<State>(*this, pump, std::move(spec))) {}

BlePeripheral::~BlePeripheral() = default;

void BlePeripheral::start(std::function<void(const std::string&)> done) {
  State& s = *state_;
  try {
    s.exportObjects();
    s.watchDevices();
  } catch (const sdbus::Error& e) {
    s.pump.kick();
    done("cannot export the GATT application on the bus: " + errorText(e));
    return;
  }
  s.checkAdapter([&s, done](const std::string& error) {
    if (!error.empty()) return done(error);
    s.registerApplication([&s, done](const std::string& error) {
      if (!error.empty()) return done(error);
      s.registerAdvertisement(done);
    });
  });
}

void BlePeripheral::stop(std::function<void()> done) {
  State& s = *state_;
  auto pending = std::make_shared<int>(0);
  auto answered = [pending, done](const sdbus::Error*) {
    if (--*pending == 0) done();
  };
  if (s.advertising) {
    ++*pending;
    s.adapter->callMethodAsync("UnregisterAdvertisement")
        .onInterface(api::kAdvertisingManager)
        .withTimeout(kCallTimeout)
        .withArguments(sdbus::ObjectPath(s.advPath))
        .uponReplyInvoke(answered);
    s.advertising = false;
  }
  if (s.appRegistered) {
    ++*pending;
    s.adapter->callMethodAsync("UnregisterApplication")
        .onInterface(api::kGattManager)
        .withTimeout(kCallTimeout)
        .withArguments(sdbus::ObjectPath(s.appPath))
        .uponReplyInvoke(answered);
    s.appRegistered = false;
  }
  s.pump.kick();
  if (*pending == 0) done();
}

bool BlePeripheral::notify(std::span<const std::uint8_t> value) {
  State& s = *state_;
  if (!s.notifying) {
    log::debug(kComponent, "not subscribed: dropped " + toHex(value));
    return false;
  }
  log::debug(kComponent, "notify " + toHex(value));
  s.value.assign(value.begin(), value.end());
  // BlueZ turns a PropertiesChanged on Value into a notification to every subscribed central
  // (gatt-api "StartNotify"); the signal carries the value, so back-to-back frames all go out.
  s.notifyChar->emitPropertiesChangedSignal(api::kGattCharacteristic, {"Value"});
  s.pump.kick();
  return true;
}

void BlePeripheral::disconnectCentral() {
  State& s = *state_;
  if (s.peer.empty()) return;
  s.device = sdbus::createProxy(s.conn, api::kService, s.peer);
  s.device->callMethodAsync("Disconnect")
      .onInterface(api::kDevice)
      .withTimeout(kCallTimeout)
      .uponReplyInvoke([](const sdbus::Error* e) {
        if (e) log::warn(kComponent, "cannot drop the central: " + errorText(*e));
      });
  s.pump.kick();
}

const std::string& BlePeripheral::advertisedName() const {
  return state_->advertisedName;
}

bool BlePeripheral::connected() const {
  return state_->linkUp;
}

}  // namespace pitwall
