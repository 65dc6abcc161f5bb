#pragma once
// A fake `org.bluez` for tests: BlueZ 5.66's D-Bus API (adapter-api, device-api, gatt-api) served
// with sdbus-c++ adaptors, whose cars are simulated Anki cars (sim::World) on the same loop.
//
// Everything runs on the engine loop (real clock): FakeBluez drives its D-Bus connection with a
// DbusPump of its own, so nobody else may pump that connection. Where the fake differs from real
// BlueZ is written at the top of fake_bluez.cpp.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/protocol/alphabot/ble_codec.hpp"
#include "engine/sim/world.hpp"
#include "engine/transport/dbus_pump.hpp"

namespace sdbus {
class IConnection;
}

namespace pitwall::testing {

class FakeAlphabot;

struct FakeBluezOptions {
  int adapters = 1;                    // hci0, hci1, …
  int cars = 1;                        // car i sits on adapter i % adapters
  std::string track = "oval";          // a layout name or file (sim::loadLayout)
  std::uint64_t seed = 1;              // the world's seed, and the RSSI jitter's
  std::string sensor = "real";         // the cars' sensor model (engine/sim/sensor.hpp)
  std::vector<std::string> addresses;  // car i's address; default E0:00:00:00:00:<i+1>
  std::vector<std::string> names;      // car i's user name; default from the grid
  bool noAcquire = false;  // AcquireNotify/AcquireWrite → org.bluez.Error.NotSupported
  // Alphabot robots (tests/fake_bluez/fake_alphabot.hpp), after the cars: robot i sits on
  // adapter (cars + i) % adapters; its address is alphabotAddresses[i], else AB:00:00:00:00:<i+1>.
  int alphabots = 0;
  std::vector<std::string> alphabotAddresses;
  // Devices that are not cars, already connected when the fake starts (a gamepad, a phone):
  // "NAME" on hci0 or "NAME@hciN"; addresses BB:00:00:00:00:<i+1>, the HID service's UUID.
  std::vector<std::string> bystanders;
};

// What happened to one device, for tests to check.
struct FakeBluezCounters {
  int connectCalls = 0;            // Device1.Connect calls received
  int connects = 0;                // connections made
  int disconnects = 0;             // connections that ended (client, fault, or the car)
  std::size_t framesToCar = 0;     // frames written by the client (WriteValue or fd)
  std::size_t framesToClient = 0;  // car frames delivered (PropertiesChanged or fd)
  std::size_t framesDropped = 0;   // car frames nobody was subscribed to
  int connectsInProgress = 0;      // Connect calls answered InProgress (one was pending)
  int connectsCancelled = 0;       // pending Connects a Disconnect cancelled
  int notifiesAbandoned = 0;       // Disconnects while AcquireNotify waited (NotifySlow)
};

class FakeBluez {
 public:
  using Options = FakeBluezOptions;
  using Counters = FakeBluezCounters;
  // A device's faults (a time after its first connection, and for how long where it lasts):
  //   Drop       the link drops; the device stays known (and connectable)
  //   Burst      three drops, 1.5 s apart
  //   Vanish     the link drops and the device is gone for good
  //   Garbage    malformed frames (garbageFrames)
  //   Reboot     the car resets (sim::World::Vehicle::reboot): the link drops, the car stops,
  //              leaves SDK mode and its place on the map, and is not connectable for `lasting`
  //   Mute       its notifications are lost for `lasting` (the link stays up)
  //   WriteFail  the write socket closes, and writes (WriteValue, AcquireWrite) fail for `lasting`
  //   WriteHang  the write socket is not read for `lasting` (what was written arrives late)
  //   ConnectHang  the link drops and for `lasting` a connection attempt neither succeeds nor
  //              fails (the car does not answer; BlueZ keeps trying, and a second Connect is
  //              answered InProgress) until Disconnect cancels it or the time is over
  //   NotifyHeld the link drops and for `lasting` the car's notifications are held by a request
  //              bluetoothd abandoned: AcquireNotify and StartNotify are refused NotPermitted
  //              "Notify acquired" (BlueZ 5.66, a disconnect during AcquireNotify: fixed in 5.84)
  //   NotifySlow the link drops, and on the next connection the car confirms its notification
  //              setting `lasting` late: AcquireNotify is answered only then. A Disconnect while it
  //              waits does what BlueZ before 5.84 does: the notifications stay held (NotifyHeld)
  //              until the device is removed or bluetoothd restarts
  enum class Fault {
    Drop,
    Burst,
    Vanish,
    Garbage,
    Reboot,
    Mute,
    WriteFail,
    WriteHang,
    ConnectHang,
    NotifyHeld,
    NotifySlow
  };

  // Exports the adapters, then requests the name org.bluez on `connection` (unless the
  // connection already owns it). Throws std::invalid_argument for bad options (unknown track,
  // malformed address) and sdbus::Error when the bus refuses.
  FakeBluez(Loop& loop, sdbus::IConnection& connection, Options options = {});
  ~FakeBluez();
  FakeBluez(const FakeBluez&) = delete;
  FakeBluez& operator=(const FakeBluez&) = delete;

  // Ground truth.
  sim::World& world();
  sim::SimCar& car(std::string_view address);              // throws std::out_of_range
  std::vector<std::string> addresses() const;              // car order (cars only)
  std::vector<std::string> alphabotAddresses() const;      // robot order
  FakeAlphabot& alphabot(std::string_view address);        // throws std::out_of_range
  std::string adapterPath(int index) const;                // "/org/bluez/hci0"
  std::string devicePath(std::string_view address) const;  // where its object is (or would be)
  bool exported(std::string_view address) const;           // its Device1 object is on the bus
  bool connected(std::string_view address) const;
  const Counters& counters(std::string_view address) const;
  DbusPump& pump();

  // Faults. Each takes effect now (and kicks the pump).
  void refuse(std::string_view address, bool refused = true);  // Connect fails
  void drop(std::string_view address);    // the link drops; the device stays known
  void vanish(std::string_view address);  // disconnect, then the device is gone for good
  void inject(std::string_view address, std::span<const std::uint8_t> bytes);  // as a notification
  // An Alphabot notifies `bytes` on `characteristic` (malformed ones too).
  void inject(std::string_view address, alphabot::ble::Characteristic characteristic,
              std::span<const std::uint8_t> bytes);
  // A fault `after` the device's first successful Connect (at once if that time has passed).
  // Garbage sends garbageFrames().
  void schedule(Fault fault, std::string_view address, Duration after, Duration lasting = {});
  // The controller hciN is unplugged: its connections end and its objects leave the bus; it is
  // plugged back after `lasting` (a new object, found by InterfacesAdded). `after`: since now.
  void unplug(int adapter, Duration after, Duration lasting);
  // bluetoothd restarts: every connection ends, org.bluez leaves the bus with every object, and
  // is back after `lasting` with the adapters (devices reappear as they advertise). `after`: since
  // now.
  void restart(Duration after, Duration lasting);
  // Malformed Anki frames: a size byte larger than the frame, a 1-byte frame, an unknown id.
  static std::vector<std::vector<std::uint8_t>> garbageFrames();

  // BlueZ's Device1.Name for an advertised local name (BlueZ 5.66 eir.c name2utf8): the bytes up
  // to the first NUL, non-ASCII bytes made spaces, whitespace stripped. Empty: no Name property.
  static std::string bluezName(std::span<const std::uint8_t> localName);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace pitwall::testing
