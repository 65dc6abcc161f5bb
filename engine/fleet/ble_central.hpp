#pragma once
// Real Anki cars over Bluetooth LE (docs/bluetooth.md): finds them, adds them to the fleet, keeps
// them connected.
//
//  - Scan: discovery on every chosen adapter for the scan time (shorter when every car asked for
//    with --car is found). A car seen by several adapters goes to the one holding fewest cars,
//    and none is given more than carsPerAdapter.
//  - Connect: one car at a time per adapter (controllers handle concurrent LE connection setup
//    badly), in a queue.
//  - Keep: a car that drops is reconnected with backoff (0.5 s doubling to 8 s); a car that
//    vanishes from BlueZ is looked for again with discovery on its adapter.
//  - Shutdown: every car disconnected (the session has stopped them first).
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "engine/fleet/fleet.hpp"
#include "engine/transport/ble_link.hpp"
#include "engine/transport/bluez.hpp"

namespace pitwall::ble {

struct CentralOptions {
  std::vector<std::string> adapters;  // names (hci0) or addresses; empty: every adapter
  std::vector<std::string> cars;      // addresses; empty: every Anki car found
  Duration scan = std::chrono::seconds(5);
  // Cars one controller is given at most (docs/bluetooth.md "Adapters"): a car seen only by
  // adapters that hold as many is left out, with a sentence.
  int carsPerAdapter = 6;
  // BlueZ's configuration, for the connection interval it asks each car for
  // (connection_interval.hpp): said per adapter, with a warning when too short for its cars.
  std::string bluezConfig = "/etc/bluetooth/main.conf";
  Duration backoffMin = std::chrono::milliseconds(500);
  Duration backoffMax = std::chrono::seconds(8);
  LinkTimeouts timeouts;
};

// One car found by a scan.
struct Sighting {
  std::string address;
  std::map<std::string, std::string>
      paths;      // adapter path → device path, every adapter that saw it
  Device device;  // as last seen (on any adapter)
};

// Scans `adapters` for Anki cars for `duration` (or until every address in `wanted` is seen);
// done(error, sightings ordered by address). Used by `pitwall scan` and by Central::start.
void scanForCars(Bluez& bluez, const std::vector<const Adapter*>& adapters, Duration duration,
                 const std::vector<std::string>& wanted,
                 std::function<void(std::optional<std::string>, std::vector<Sighting>)> done);

class Central {
 public:
  Central(Loop& loop, Fleet& fleet, CentralOptions options);  // throws BleError (no bus)
  ~Central();
  Central(const Central&) = delete;
  Central& operator=(const Central&) = delete;

  // Reads BlueZ, scans, adds every car found to the fleet and connects them. done(error) after
  // every car's first attempt: an error when BlueZ cannot be used or no car was found. Cars whose
  // first attempt failed keep being retried.
  void start(std::function<void(std::optional<std::string> error)> done);
  // Stops reconnecting and disconnects every car; done() when all are down (bounded by the
  // links' disconnect timeout).
  void shutdown(std::function<void()> done);

  // After shutdown() (or at any time): scans again, adds the cars not known yet, and connects
  // every car that is not connected (the MQTT connection intent).
  void reconnect();

  Bluez& bluez() { return *bluez_; }
  std::size_t carCount() const { return cars_.size(); }
  // Connection attempts so far, for tests: address → attempts.
  std::map<std::string, int> attempts() const;

 private:
  struct Car;
  struct AdapterQueue {
    std::deque<Car*> waiting;
    Car* busy = nullptr;
    int discoverers = 0;  // cars that vanished and are looked for on this adapter
  };
  void addCars(const std::vector<Sighting>& sightings);
  void enqueue(Car& car);
  void pump(AdapterQueue& queue);
  void connected(Car& car, std::optional<std::string> error);
  void retryLater(Car& car, const std::string& why);
  void vanished(Car& car);
  void deviceSeen(const Device& device);
  void maybeFinishFirstRound();

  Loop& loop_;
  Fleet& fleet_;
  CentralOptions options_;
  std::unique_ptr<Bluez> bluez_;
  std::vector<std::unique_ptr<Car>> cars_;
  std::map<std::string, AdapterQueue> queues_;  // by adapter path
  std::map<std::string, int> intervalTold_;     // by adapter path: the cars it was said for
  std::function<void(std::optional<std::string>)> firstRoundDone_;
  bool shuttingDown_ = false;
  std::shared_ptr<bool> alive_;
};

}  // namespace pitwall::ble
