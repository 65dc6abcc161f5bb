#pragma once
// A virtual-time run of simulated cars on the oval, for the benchmarks (sim_bench.cpp, and
// cli_bench.cpp's in-process half of the --fast comparison).
#include <cmath>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "bindings/script_host.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/sim/grid.hpp"
#include "engine/sim/track.hpp"
#include "engine/sim/world.hpp"
#include "tests/support/sim_cars.hpp"

namespace pitwall::bench {

inline constexpr int kSpeed =
    800;  // mm/s: well below the speed that throws a car off the oval's curves

// Car `index` of `count`, spread evenly along the lap, four lanes, so that no two share a spot
// and cars in one lane keep their spacing. (gridSpec goes back one piece per row of four, which
// wraps round the oval's 10 pieces after 40 cars.)
inline sim::CarSpec spreadSpec(const sim::Track& track, int index, int count) {
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

inline double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

}  // namespace pitwall::bench
