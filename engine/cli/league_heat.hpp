#pragma once
// One heat of a league (pitwall league, docs/league.md): its drivers' files raced in the
// simulator in virtual time, in this process, each file in a driver world of its own
// (docs/drivers.md) — or one driver alone for qualifying. The result's `data` is the heat's rows
// as JSON: [{number, car, position, status, reason?, finished, laps, bestLap?, totalTime?,
// lapTimes}], car N being driven by files[N-1].
#include <cstdint>
#include <string>
#include <vector>

#include "bindings/script_host.hpp"
#include "engine/cli/scenario.hpp"

namespace pitwall::cli {

struct HeatSpec {
  std::vector<std::string> files;  // in grid order: car 1 (pole) is files[0]
  bool qualifying = false;         // each car on its own, best lap (race.qualifying)
  int laps = 5;
  std::string track = "oval";
  std::string sensor = "real";  // the simulated cars' sensor model (docs/simulator.md)
  std::uint64_t seed = 1;
  std::string title;
  DriverLimits limits;
  // `data` is {"rows": [...], "trace": [{time, lap, distance, speed}]} instead: car 1's laps
  // counted, lap distance (mm) and speed (mm/s) as the simulator knows them, every 0.05 s
  // (pitwall try)
  bool trace = false;
};

ScenarioResult runHeat(const HeatSpec& spec);

}  // namespace pitwall::cli
