#pragma once
// One run on the built-in simulator, as `pitwall run` and `pitwall test` set it up: the loop,
// the world, the fleet of simulated cars and the Lua host, destroyed in the right order.
#include <memory>
#include <string>

#include "bindings/script_host.hpp"
#include "engine/core/loop.hpp"
#include "engine/vehicles/fleet.hpp"
#include "engine/vehicles/recorder.hpp"

namespace pitwall::cli {

class SimRun {
 public:
  SimRun(ClockKind clock, sim::Track track, std::uint64_t seed);
  ~SimRun();

  Loop& loop() { return loop_; }
  Fleet& fleet() { return fleet_; }
  SimSession& sim() { return sim_; }
  ScriptHost& host() { return *host_; }

  void record(const std::string& path);  // throws std::runtime_error naming the file
  // Puts `count` cars on the starting grid and runs the loop until all are connected.
  bool addGridCars(int count);
  void startHost(HostOptions options);
  // Stops every car, lets the stop frames reach them, then ends loop().run().
  void finish();

 private:
  Loop loop_;  // first made, last destroyed: everything below schedules on it
  SimSession sim_;
  Fleet fleet_;
  std::unique_ptr<Recorder> recorder_;
  std::unique_ptr<ScriptHost> host_;
  bool finishing_ = false;
};

}  // namespace pitwall::cli
