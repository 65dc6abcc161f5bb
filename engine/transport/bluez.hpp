#pragma once
// The BlueZ object tree as a client sees it over D-Bus (docs/bluetooth.md): adapters, devices and
// GATT characteristics of org.bluez, kept current from ObjectManager and PropertiesChanged
// signals. Everything runs on the engine loop through a DbusPump; every call is asynchronous.
//
// Production code opens the system bus; tests point DBUS_SYSTEM_BUS_ADDRESS at a private bus
// with a fake org.bluez (tests/fake_bluez), and the same code runs unchanged.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/transport/bluez_api.hpp"
#include "engine/transport/dbus_pump.hpp"

namespace sdbus {
class IConnection;
class IProxy;
class Error;
}  // namespace sdbus

namespace pitwall::ble {

inline constexpr const char* kService = api::kService;
inline constexpr const char* kAdapterIface = api::kAdapter;
inline constexpr const char* kDeviceIface = api::kDevice;
inline constexpr const char* kCharIface = api::kGattCharacteristic;

// A failure a user can act on, said in one sentence (no adapter, BlueZ not running, …).
struct BleError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Adapter {
  std::string path;  // /org/bluez/hci0
  std::string name;  // hci0
  std::string address;
  bool powered = false;
  bool discovering = false;
};

struct Device {
  std::string path, adapter;  // object paths
  std::string address, name;  // name: BlueZ's Name (the local name cut at its first NUL)
  std::vector<std::string> uuids;
  std::optional<anki::ManufacturerData> manufacturer;
  std::optional<std::vector<std::uint8_t>> rawName;  // AdvertisingData 0x09, where BlueZ has it
  std::optional<int> rssi;
  bool connected = false;
  bool servicesResolved = false;

  bool isAnki() const;  // advertises the Anki service, or Anki manufacturer data
  // The Anki local name: from the raw advertising data where BlueZ has it (only experimentally,
  // and not in 5.66), else from what BlueZ made of it in Name: the bytes up to the first NUL —
  // the state byte and the version when they contain no zero, never the user name (which comes
  // after reserved NUL bytes). A whole Anki-shaped Name, with control characters where a real
  // car has the NULs (pitwall emulate-car, anki::localNameText), gives all of it. Any other Name
  // is taken as the user name (a car emulator that advertises a plain name).
  anki::LocalName localName() const;
  bool stateKnown() const;  // the state byte and version were readable
};

struct Characteristic {
  std::string path, uuid;
  std::vector<std::string> flags;
};

// "org.freedesktop.DBus.Error.ServiceUnknown: …" → a sentence for the user, naming the step.
std::string describe(const sdbus::Error& error, const std::string& step);

class Bluez {
 public:
  // Opens the system bus. Throws BleError when there is none.
  explicit Bluez(Loop& loop);
  ~Bluez();
  Bluez(const Bluez&) = delete;
  Bluez& operator=(const Bluez&) = delete;

  // Reads the whole tree (GetManagedObjects); done(error) on the loop. Signals are followed from
  // before the read, so nothing that changes meanwhile is missed.
  void start(std::function<void(std::optional<std::string> error)> done);

  const std::map<std::string, Adapter>& adapters() const { return adapters_; }
  const std::map<std::string, Device>& devices() const { return devices_; }
  const Device* device(const std::string& path) const;
  std::vector<const Characteristic*> characteristicsOf(const std::string& devicePath) const;
  // Adapters by name (hci0), all when `names` is empty; throws BleError naming what is missing.
  std::vector<const Adapter*> pickAdapters(const std::vector<std::string>& names) const;

  // Discovery of LE devices on one adapter: those advertising one of `serviceUuids` (the Anki
  // service unless told otherwise), every LE device when it is empty.
  void startDiscovery(const std::string& adapter,
                      std::function<void(std::optional<std::string> error)> done,
                      std::vector<std::string> serviceUuids = {std::string(anki::kServiceUuid)});
  void stopDiscovery(const std::string& adapter, std::function<void()> done = {});

  // A method call on org.bluez; reply(error or nullptr, reply message) on the loop.
  sdbus::IProxy& proxy(const std::string& path);
  DbusPump& pump() { return *pump_; }
  Loop& loop() { return loop_; }

  // Change notifications, one subscriber each (the Central, or the scan command).
  std::function<void(const Device&)> onDevice;  // added or changed
  std::function<void(const std::string& path)> onDeviceRemoved;
  std::function<void(const std::string& charPath, const std::vector<std::uint8_t>&)> onValue;
  // org.bluez is back on the bus (bluetoothd restarted) and its tree has been read again. When
  // it left, every device was reported removed through onDeviceRemoved.
  std::function<void()> onBluezBack;
  // A controller that can scan again: plugged in (its Adapter1 object added) or powered on.
  std::function<void(const std::string& adapterPath)> onAdapterReady;

 private:
  struct Signals;      // the signal subscriptions (sdbus slots and the proxy of "/")
  friend struct Tree;  // bluez.cpp: applies signal and reply contents to the maps below
  void reset();        // forget everything (org.bluez left the bus)

  Loop& loop_;
  std::unique_ptr<sdbus::IConnection> connection_;
  std::unique_ptr<DbusPump> pump_;
  std::unique_ptr<Signals> signals_;
  std::map<std::string, std::unique_ptr<sdbus::IProxy>> proxies_;
  std::map<std::string, Adapter> adapters_;
  std::map<std::string, Device> devices_;
  std::map<std::string, Characteristic> chars_;
  std::shared_ptr<bool> alive_;
};

}  // namespace pitwall::ble
