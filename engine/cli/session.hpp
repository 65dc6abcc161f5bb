#pragma once
// One run, as `pitwall run` and `pitwall test` set it up: the loop, the cars (simulated in a
// world, or real ones over Bluetooth LE) and the Lua host, destroyed in the right order.
#include <memory>
#include <string>

#include "bindings/reloader.hpp"
#include "engine/core/loop.hpp"
#include "engine/vehicles/ble_central.hpp"
#include "engine/vehicles/fleet.hpp"
#include "engine/vehicles/recorder.hpp"

namespace pitwall::cli {

class Session {
 public:
  // On the built-in simulator.
  Session(ClockKind clock, sim::Track track, std::uint64_t seed);
  // Real cars through BlueZ, on the real clock. Throws ble::BleError when there is no bus.
  explicit Session(ble::CentralOptions options);
  ~Session();

  Loop& loop() { return loop_; }
  Fleet& fleet() { return fleet_; }
  SimSession& sim() { return sim_; }
  ScriptHost& host() { return scripts_->host(); }  // the Lua world now (hot reload replaces it)
  Reloader& scripts() { return *scripts_; }

  void record(const std::string& path);  // throws std::runtime_error naming the file
  // Puts `count` cars on the starting grid and runs the loop until all are connected.
  bool addGridCars(int count);
  // Finds and connects the real cars (runs the loop until every car had a first attempt).
  std::optional<std::string> connectRealCars();
  void startHost(HostOptions options);
  // Stops every car, lets the stop frames reach them, disconnects real cars, then ends
  // loop().run().
  void finish();

 private:
  Loop loop_;  // first made, last destroyed: everything below schedules on it
  SimSession sim_;
  Fleet fleet_;
  std::unique_ptr<Recorder> recorder_;
  std::unique_ptr<ble::Central> central_;  // real cars; after the fleet: its links live there
  std::unique_ptr<Reloader> scripts_;
  bool finishing_ = false;
};

}  // namespace pitwall::cli
