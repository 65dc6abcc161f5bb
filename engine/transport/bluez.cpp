#include "engine/transport/bluez.hpp"

#include <sdbus-c++/sdbus-c++.h>

#include <algorithm>

#include "engine/core/log.hpp"

namespace pitwall::ble {

using Properties = std::map<std::string, sdbus::Variant>;
using Interfaces = std::map<std::string, Properties>;
using ManagedObjects = std::map<sdbus::ObjectPath, Interfaces>;

namespace {

using api::kObjectManager;

// BlueZ's types are fixed by its API, but a broken or foreign peer must not crash us: a property
// of an unexpected type is treated as absent.
template <class T>
std::optional<T> take(const sdbus::Variant& v) {
  try {
    if (!v.containsValueOfType<T>()) return std::nullopt;
    return v.get<T>();
  } catch (const sdbus::Error&) {
    return std::nullopt;
  }
}

std::string lastComponent(const std::string& path) {
  auto slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

}  // namespace

bool Device::isAnki() const {
  if (manufacturer) return true;
  return std::any_of(uuids.begin(), uuids.end(),
                     [](const std::string& u) { return lower(u) == anki::kServiceUuid; });
}

namespace {
bool stateByte(unsigned char b) {
  return (b & ~0x70u) == 0;
}  // bits 0x10, 0x20, 0x40 only

std::span<const std::uint8_t> bytesOf(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

// What BlueZ's Name keeps of an Anki local name whose reserved bytes are zero (drive-sdk's
// description; the captured real cars' are not): a non-zero state byte and at most the version.
bool cutAnkiName(const std::string& name) {
  return !name.empty() && name.size() <= 3 && name[0] != 0 &&
         stateByte(static_cast<unsigned char>(name[0]));
}
}  // namespace

anki::LocalName Device::localName() const {
  if (rawName) {
    if (anki::isAnkiLocalName(*rawName)) return anki::parseLocalName(*rawName);
    anki::LocalName n;  // a plain name
    n.user_name = std::string(rawName->begin(), std::find(rawName->begin(), rawName->end(), 0));
    return n;
  }
  // A whole Anki-shaped name in Name: a real car's whose reserved bytes are not zero (the captured
  // ones, cut at the zero after the user name) and an emulated car's (anki::localNameText).
  if (anki::isAnkiLocalName(bytesOf(name))) return anki::parseLocalName(bytesOf(name));
  if (cutAnkiName(name)) {
    auto n = anki::parseLocalName(bytesOf(name));
    n.user_name.clear();
    if (name.size() < 3) n.version = 0;
    return n;
  }
  anki::LocalName n;
  n.user_name = name;
  return n;
}

bool Device::stateKnown() const {
  return rawName ? anki::isAnkiLocalName(*rawName)
                 : anki::isAnkiLocalName(bytesOf(name)) || cutAnkiName(name);
}

std::string describe(const sdbus::Error& error, const std::string& step) {
  const std::string& n = error.getName();
  if (n == "org.freedesktop.DBus.Error.ServiceUnknown" ||
      n == "org.freedesktop.DBus.Error.NameHasNoOwner")
    return "BlueZ is not running (" + step +
           "): start it, e.g. `systemctl start bluetooth` (docs/bluetooth.md)";
  // (the bus's policy, or BlueZ's authorization: not org.bluez.Error.NotPermitted, which is
  // BlueZ saying that the operation is not allowed now, with why)
  if (n == "org.freedesktop.DBus.Error.AccessDenied" || n == "org.bluez.Error.NotAuthorized")
    return "no permission to use BlueZ (" + step +
           "): run as root or as a member of the `bluetooth` group (docs/bluetooth.md)";
  if (n == "org.bluez.Error.NotPermitted" && error.getMessage() == "Notify acquired")
    return step +
           " refused: bluetoothd still holds an earlier request for these notifications that it "
           "gave up on (org.bluez.Error.NotPermitted: Notify acquired; a bluetoothd bug before "
           "BlueZ 5.84, after a connection lost while notifications were being enabled): remove "
           "the car from BlueZ (`bluetoothctl remove` and its address) or restart bluetoothd "
           "(docs/bluetooth.md)";
  if (n == "org.freedesktop.DBus.Error.NoReply" || n == "org.freedesktop.DBus.Error.Timeout")
    return step + " timed out";
  std::string msg = error.getMessage();
  return step + " failed: " + (msg.empty() ? n : msg) + " (" + n + ")";
}

// Applies what BlueZ says (a reply or a signal) to the client's maps and tells the subscriber.
struct Tree {
  static void apply(Bluez& b, const std::string& path, const std::string& iface,
                    const Properties& props, const std::vector<std::string>& invalidated,
                    bool announce) {
    if (iface == kAdapterIface) {
      auto& a = b.adapters_[path];
      a.path = path;
      a.name = lastComponent(path);
      if (auto it = props.find("Address"); it != props.end())
        if (auto v = take<std::string>(it->second)) a.address = *v;
      if (auto it = props.find("Powered"); it != props.end())
        if (auto v = take<bool>(it->second)) a.powered = *v;
      if (auto it = props.find("Discovering"); it != props.end())
        if (auto v = take<bool>(it->second)) a.discovering = *v;
    } else if (iface == kDeviceIface) {
      auto& d = b.devices_[path];
      d.path = path;
      for (const auto& [key, value] : props) {
        if (key == "Address") {
          if (auto v = take<std::string>(value)) d.address = *v;
        } else if (key == "Name") {
          if (auto v = take<std::string>(value)) d.name = *v;
        } else if (key == "Adapter") {
          if (auto v = take<sdbus::ObjectPath>(value)) d.adapter = *v;
        } else if (key == "UUIDs") {
          if (auto v = take<std::vector<std::string>>(value)) d.uuids = *v;
        } else if (key == "RSSI") {
          if (auto v = take<std::int16_t>(value)) d.rssi = *v;
        } else if (key == "Connected") {
          if (auto v = take<bool>(value)) d.connected = *v;
        } else if (key == "ServicesResolved") {
          if (auto v = take<bool>(value)) d.servicesResolved = *v;
        } else if (key == "ManufacturerData") {
          auto m = take<std::map<std::uint16_t, sdbus::Variant>>(value);
          if (!m) continue;
          for (const auto& [company, data] : *m)
            if (auto bytes = take<std::vector<std::uint8_t>>(data))
              if (auto parsed = anki::parseManufacturerData(company, *bytes))
                d.manufacturer = *parsed;
        } else if (key == "AdvertisingData") {
          auto m = take<std::map<std::uint8_t, sdbus::Variant>>(value);
          if (!m) continue;
          if (auto it = m->find(0x09); it != m->end())  // Complete Local Name
            if (auto bytes = take<std::vector<std::uint8_t>>(it->second)) d.rawName = *bytes;
        }
      }
      for (const auto& key : invalidated)
        if (key == "RSSI") d.rssi.reset();
      if (d.adapter.empty()) d.adapter = path.substr(0, path.rfind('/'));
      if (announce && b.onDevice) b.onDevice(d);
    } else if (iface == kCharIface) {
      auto& c = b.chars_[path];
      c.path = path;
      for (const auto& [key, value] : props) {
        if (key == "UUID") {
          if (auto v = take<std::string>(value)) c.uuid = lower(*v);
        } else if (key == "Flags") {
          if (auto v = take<std::vector<std::string>>(value)) c.flags = *v;
        } else if (key == "Value" && announce && b.onValue) {
          if (auto v = take<std::vector<std::uint8_t>>(value)) b.onValue(path, *v);
        }
      }
    }
  }

  static void remove(Bluez& b, const std::string& path, const std::vector<std::string>& ifaces) {
    for (const auto& iface : ifaces) {
      if (iface == kAdapterIface) {
        b.adapters_.erase(path);
      } else if (iface == kDeviceIface) {
        if (b.devices_.erase(path) && b.onDeviceRemoved) b.onDeviceRemoved(path);
      } else if (iface == kCharIface) {
        b.chars_.erase(path);
      }
    }
  }
};

struct Bluez::Signals {
  sdbus::Slot objects, properties, owner;
};

Bluez::Bluez(Loop& loop) : loop_(loop), alive_(std::make_shared<bool>(true)) {
  try {
    connection_ = sdbus::createSystemBusConnection();
  } catch (const sdbus::Error& e) {
    throw BleError("cannot reach the system D-Bus, which BlueZ is on (" + e.getMessage() +
                   "): is dbus running? (docs/bluetooth.md)");
  }
  // Follow the tree from before it is read: a change between the read and the first signal
  // would be lost otherwise. The matches are added synchronously, before the loop runs. They
  // select by path, not by sender='org.bluez': sd-bus also filters signals locally, against the
  // sender's unique name, so a well-known sender name never matches there.
  signals_ = std::make_unique<Signals>();
  signals_->objects = connection_->addMatch(
      "type='signal',interface='org.freedesktop.DBus.ObjectManager',path='/',"
      "arg0path='/org/bluez/'",
      [this](sdbus::Message& msg) {
        sdbus::ObjectPath path;
        msg >> path;
        if (msg.getMemberName() == "InterfacesAdded") {
          Interfaces ifaces;
          msg >> ifaces;
          // Device1 last: a device announced with its characteristics already known
          for (const auto& [iface, props] : ifaces)
            if (iface != kDeviceIface) Tree::apply(*this, path, iface, props, {}, true);
          if (auto it = ifaces.find(kDeviceIface); it != ifaces.end())
            Tree::apply(*this, path, it->first, it->second, {}, true);
          if (ifaces.count(kAdapterIface) && onAdapterReady) onAdapterReady(path);
        } else if (msg.getMemberName() == "InterfacesRemoved") {
          std::vector<std::string> ifaces;
          msg >> ifaces;
          Tree::remove(*this, path, ifaces);
        }
      });
  signals_->properties = connection_->addMatch(
      "type='signal',interface='org.freedesktop.DBus.Properties',member='PropertiesChanged',"
      "path_namespace='/org/bluez'",
      [this](sdbus::Message& msg) {
        std::string iface;
        Properties changed;
        std::vector<std::string> invalidated;
        msg >> iface >> changed >> invalidated;
        Tree::apply(*this, msg.getPath(), iface, changed, invalidated, true);
        if (iface == kAdapterIface && onAdapterReady)
          if (auto it = changed.find("Powered"); it != changed.end())
            if (auto on = take<bool>(it->second); on && *on) onAdapterReady(msg.getPath());
      });
  signals_->owner = connection_->addMatch(
      "type='signal',sender='org.freedesktop.DBus',interface='org.freedesktop.DBus',"
      "member='NameOwnerChanged',arg0='org.bluez'",
      [this](sdbus::Message& msg) {
        std::string name, oldOwner, newOwner;
        msg >> name >> oldOwner >> newOwner;
        if (!oldOwner.empty()) {
          log::warn("ble", "BlueZ left the bus: every car is disconnected");
          reset();
        }
        if (newOwner.empty()) return;
        // bluetoothd (re)started: read its tree again, then let the subscriber go on
        log::info("ble", "BlueZ is on the bus again");
        start([this](std::optional<std::string> error) {
          if (error) return log::warn("ble", *error);
          if (onBluezBack) onBluezBack();
        });
      });
  pump_ = std::make_unique<DbusPump>(loop_, *connection_);
}

Bluez::~Bluez() {
  *alive_ = false;
  proxies_.clear();  // pending calls are cancelled with their proxies
  signals_.reset();
  pump_.reset();
}

void Bluez::reset() {
  std::vector<std::string> gone;
  for (const auto& [path, d] : devices_) gone.push_back(path);
  adapters_.clear();
  devices_.clear();
  chars_.clear();
  if (onDeviceRemoved)
    for (const auto& p : gone) onDeviceRemoved(p);
}

sdbus::IProxy& Bluez::proxy(const std::string& path) {
  auto& p = proxies_[path];
  if (!p) p = sdbus::createProxy(*connection_, kService, path);
  return *p;
}

void Bluez::start(std::function<void(std::optional<std::string> error)> done) {
  std::weak_ptr<bool> alive = alive_;
  proxy("/")
      .callMethodAsync("GetManagedObjects")
      .onInterface(kObjectManager)
      .withTimeout(std::chrono::seconds(5))
      .uponReplyInvoke([this, alive, done](const sdbus::Error* error, ManagedObjects objects) {
        if (alive.expired()) return;
        if (error) return done(describe(*error, "reading BlueZ's objects"));
        for (const auto& [path, ifaces] : objects)
          for (const auto& [iface, props] : ifaces)
            Tree::apply(*this, path, iface, props, {}, false);
        done(std::nullopt);
      });
  pump_->kick();
}

const Device* Bluez::device(const std::string& path) const {
  auto it = devices_.find(path);
  return it == devices_.end() ? nullptr : &it->second;
}

std::vector<const Characteristic*> Bluez::characteristicsOf(const std::string& devicePath) const {
  std::vector<const Characteristic*> out;
  std::string prefix = devicePath + "/";
  for (auto it = chars_.lower_bound(prefix); it != chars_.end(); ++it) {
    if (it->first.compare(0, prefix.size(), prefix) != 0) break;
    out.push_back(&it->second);
  }
  return out;
}

std::vector<const Adapter*> Bluez::pickAdapters(const std::vector<std::string>& names) const {
  std::vector<const Adapter*> out;
  std::string found;
  for (const auto& [path, a] : adapters_) found += (found.empty() ? "" : ", ") + a.name;
  if (adapters_.empty())
    throw BleError(
        "no Bluetooth adapter found: plug one in, or check `bluetoothctl list` "
        "(docs/bluetooth.md)");
  if (names.empty()) {
    for (const auto& [path, a] : adapters_) out.push_back(&a);
  } else {
    for (const auto& n : names) {
      auto it = std::find_if(adapters_.begin(), adapters_.end(), [&](const auto& kv) {
        return kv.second.name == n || kv.second.address == n;
      });
      if (it == adapters_.end())
        throw BleError("there is no Bluetooth adapter " + n + " (found: " + found + ")");
      if (std::find(out.begin(), out.end(), &it->second) == out.end()) out.push_back(&it->second);
    }
  }
  for (const auto* a : out)
    if (!a->powered)
      throw BleError("Bluetooth adapter " + a->name +
                     " is powered off: switch it on with `bluetoothctl power on` (or "
                     "`rfkill unblock bluetooth` if it is blocked)");
  return out;
}

void Bluez::startDiscovery(const std::string& adapter,
                           std::function<void(std::optional<std::string> error)> done,
                           std::vector<std::string> serviceUuids) {
  std::weak_ptr<bool> alive = alive_;
  Properties filter;
  if (!serviceUuids.empty()) filter["UUIDs"] = sdbus::Variant(std::move(serviceUuids));
  filter["Transport"] = sdbus::Variant(std::string("le"));
  filter["DuplicateData"] = sdbus::Variant(true);  // RSSI updates while scanning
  auto& p = proxy(adapter);
  p.callMethodAsync("SetDiscoveryFilter")
      .onInterface(kAdapterIface)
      .withTimeout(std::chrono::seconds(5))
      .withArguments(filter)
      .uponReplyInvoke([this, alive, adapter, done](const sdbus::Error* error) {
        if (alive.expired()) return;
        if (error) return done(describe(*error, "setting the discovery filter on " + adapter));
        proxy(adapter)
            .callMethodAsync("StartDiscovery")
            .onInterface(kAdapterIface)
            .withTimeout(std::chrono::seconds(5))
            .uponReplyInvoke([alive, adapter, done](const sdbus::Error* error) {
              if (alive.expired()) return;
              if (error && error->getName() != "org.bluez.Error.InProgress")
                return done(describe(*error, "starting discovery on " + adapter));
              done(std::nullopt);
            });
      });
  pump_->kick();
}

void Bluez::stopDiscovery(const std::string& adapter, std::function<void()> done) {
  std::weak_ptr<bool> alive = alive_;
  proxy(adapter)
      .callMethodAsync("StopDiscovery")
      .onInterface(kAdapterIface)
      .withTimeout(std::chrono::seconds(5))
      .uponReplyInvoke([alive, done](const sdbus::Error*) {
        if (alive.expired()) return;
        if (done) done();
      });
  pump_->kick();
}

}  // namespace pitwall::ble
