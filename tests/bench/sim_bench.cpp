// Simulator speed: simulated seconds per wall-clock second, cars driving laps on the oval in
// virtual time. Target: ≥ 5000× real time with 4 cars (docs/performance.md).
//
// Each iteration runs the loop for 60 simulated seconds; the cars keep driving from one
// iteration to the next. Setup (placing the cars, connecting them, getting up to speed) is not
// timed.
#include <benchmark/benchmark.h>
#include <lua.hpp>

#include <cmath>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "bindings/car_binding.hpp"
#include "bindings/script_host.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/sim/grid.hpp"
#include "engine/sim/track.hpp"
#include "engine/sim/world.hpp"
#include "tests/bench/scripts.hpp"
#include "tests/bench/sim_rig.hpp"

namespace {

using namespace pitwall;
using bench::kSpeed;
using bench::SimRig;
using bench::threadCpuSeconds;

constexpr double kSimSecondsPerIteration = 60;

// sim_s_per_wall_s is the figure of record; sim_s_per_cpu_s leaves out time the thread spent
// preempted, which is what it would be on an idle machine.
void report(benchmark::State& state, SimRig& rig, std::uint64_t framesBefore, double cpuSeconds) {
  double simSeconds = kSimSecondsPerIteration * static_cast<double>(state.iterations());
  // kIsRate divides by the benchmark's time: wall time, with UseRealTime().
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(simSeconds, benchmark::Counter::kIsRate);
  state.counters["sim_s_per_cpu_s"] = simSeconds / cpuSeconds;
  state.counters["frames_per_sim_s"] =
      static_cast<double>(rig.framesIn() - framesBefore) / simSeconds;
}

void BM_SimulatorLaps(benchmark::State& state) {
  SimRig rig(static_cast<int>(state.range(0)));
  if (rig.error.empty()) rig.setSpeeds();
  if (rig.error.empty()) rig.runFor(5);  // up to speed before timing
  if (!rig.error.empty()) {
    state.SkipWithError(rig.error.c_str());
    return;
  }
  std::uint64_t framesBefore = rig.framesIn();
  double cpuBefore = threadCpuSeconds();
  for (auto _ : state) rig.runFor(kSimSecondsPerIteration);
  double cpuSeconds = threadCpuSeconds() - cpuBefore;
  rig.checkDriving();
  if (!rig.error.empty()) {
    state.SkipWithError(rig.error.c_str());
    return;
  }
  report(state, rig, framesBefore, cpuSeconds);
}
BENCHMARK(BM_SimulatorLaps)->Arg(4)->Arg(64)->UseRealTime()->Unit(benchmark::kMillisecond);

// Lap counts seen by the script must match the simulator's own (±1: the script counts at the
// first position update after the line, the simulator at the line).
void checkLapCounts(SimRig& rig) {
  lua_State* L = rig.host->state();
  lua_getglobal(L, "laps");
  auto sims = rig.world->cars();
  const auto& cars = rig.fleet->cars();
  for (std::size_t i = 0; i < cars.size() && rig.error.empty(); ++i) {
    rig.host->cars().push(L, *cars[i]);
    lua_gettable(L, -2);
    long long counted = lua_tointeger(L, -1);
    lua_pop(L, 1);
    int truth = sims[i]->truth().laps;
    if (counted < truth - 1 || counted > truth)
      rig.error = "the script counted " + std::to_string(counted) + " laps for car " +
                  std::to_string(i + 1) + ", the simulator " + std::to_string(truth);
  }
  lua_pop(L, 1);
  if (rig.error.empty() && rig.host->errorCount() > 0) rig.error = "the script raised an error";
}

void BM_SimulatorLapsWithLua(benchmark::State& state) {
  SimRig rig(static_cast<int>(state.range(0)));
  if (rig.error.empty()) rig.startScript(bench::kLapCounter);
  if (rig.error.empty()) rig.runFor(5);
  if (!rig.error.empty()) {
    state.SkipWithError(rig.error.c_str());
    return;
  }
  std::uint64_t framesBefore = rig.framesIn();
  double cpuBefore = threadCpuSeconds();
  for (auto _ : state) rig.runFor(kSimSecondsPerIteration);
  double cpuSeconds = threadCpuSeconds() - cpuBefore;
  rig.checkDriving();
  if (rig.error.empty()) checkLapCounts(rig);
  if (!rig.error.empty()) {
    state.SkipWithError(rig.error.c_str());
    return;
  }
  report(state, rig, framesBefore, cpuSeconds);
}
BENCHMARK(BM_SimulatorLapsWithLua)->Arg(4)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
