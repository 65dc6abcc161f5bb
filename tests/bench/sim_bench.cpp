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
#include "tests/support/sim_cars.hpp"

namespace {

using namespace pitwall;

constexpr double kSimSecondsPerIteration = 60;
constexpr int kSpeed = 800;  // mm/s: well below the speed that throws a car off the oval's curves

// Car `index` of `count`, spread evenly along the lap, four lanes, so that no two share a spot
// and cars in one lane keep their spacing. (gridSpec goes back one piece per row of four, which
// wraps round the oval's 10 pieces after 40 cars.)
sim::CarSpec spreadSpec(const sim::Track& track, int index, int count) {
  sim::CarSpec spec;
  spec.model_id = sim::gridModel(index);
  spec.offset_mm = sim::kLaneOffsets[index % 4];
  int perLane = (count + 3) / 4;
  double along = track.lapLength(spec.offset_mm) * (index / 4) / perLane;
  std::size_t piece = 0;
  while (along >= track.piece(piece).length(spec.offset_mm)) {
    along -= track.piece(piece).length(spec.offset_mm);
    ++piece;
  }
  spec.piece_index = piece;
  spec.distance_mm = along;
  return spec;
}

// A virtual-time run: the oval, `count` simulated cars connected through sim links, and
// optionally a script host. Members are destroyed host → fleet → world → loop.
struct SimRig {
  Loop loop{ClockKind::Virtual};
  std::unique_ptr<sim::World> world;
  std::unique_ptr<Fleet> fleet;
  std::unique_ptr<ScriptHost> host;
  std::string error;

  explicit SimRig(int count) {
    auto track = sim::namedLayout("oval");
    if (!track) {
      error = track.error();
      return;
    }
    world = std::make_unique<sim::World>(loop, *track, 1);
    fleet = std::make_unique<Fleet>(loop);
    std::vector<std::string> names;
    for (int i = 0; i < count; ++i) {
      sim::CarSpec spec =
          count <= 4 ? sim::gridSpec(world->track(), i) : spreadSpec(world->track(), i, count);
      spec.name = anki::uniqueCarName(spec.model_id, names);
      names.push_back(spec.name);
      testing::addSimulatedCar(loop, *fleet, *world, spec);
    }
    auto total = static_cast<std::size_t>(count);
    Subscription joined = fleet->carJoined.connect([this, total](AnkiCar&) {
      if (fleet->connectedCount() == total) loop.stop();
    });
    auto timeout = loop.after(std::chrono::seconds(5), [this] { loop.stop(); });
    loop.run();
    loop.cancel(timeout);
    joined.disconnect();
    if (fleet->connectedCount() != total) error = "not every simulated car connected";
  }

  void startScript(const std::string& code) {
    host = std::make_unique<ScriptHost>(loop, *fleet, nullptr, HostOptions{});
    auto started = host->startString(code, "bench");
    if (!started) error = started.error();
  }

  void setSpeeds() {
    for (AnkiCar* car : fleet->cars())
      if (auto sent = car->setSpeed(kSpeed); !sent) error = sent.error();
  }

  void runFor(double seconds) {
    loop.after(fromSeconds(seconds), [this] { loop.stop(); });
    loop.run();
  }

  std::uint64_t framesIn() const {
    std::uint64_t n = 0;
    for (AnkiCar* car : fleet->cars()) n += car->state().frames_in;
    return n;
  }

  // The cars must be driving laps, on the track, without running into each other.
  void checkDriving() {
    for (sim::SimCar* car : world->cars()) {
      sim::Truth t = car->truth();
      if (!t.on_track || t.delocalized || t.laps == 0 || t.collisions > 0 ||
          std::abs(t.speed_mm_s - kSpeed) > 1) {
        error = "a simulated car is not driving clean laps (on track " +
                std::to_string(t.on_track) + ", laps " + std::to_string(t.laps) + ", collisions " +
                std::to_string(t.collisions) + ", speed " + std::to_string(t.speed_mm_s) + ")";
        return;
      }
    }
  }
};

double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

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
