// Lap traces (engine/laps/trace.cpp) against the simulator's ground truth: a real World, real
// SimLinks, the codec, the car model and the view's feed. Where the trace puts a car along its
// lap at a time of the lap is where the simulator had it, within a tick (5 ms: 7.5 mm at
// 1500 mm/s) when every code is read, and within a bound when position updates thin out as on a
// real car (docs/simulator.md "Sensor model").
#include "engine/laps/trace.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "engine/fleet/fleet.hpp"
#include "engine/sim/world.hpp"
#include "engine/view/feed.hpp"
#include "tests/support/sim_cars.hpp"

using namespace pitwall;

namespace {

struct Sample {
  double t = 0, distance = 0;
  int laps = 0;
};

// One car at `speed` on the oval for `seconds`; the truth sampled every millisecond.
struct Drive {
  Loop loop{ClockKind::Virtual};
  sim::World world;
  Fleet fleet{loop};
  view::Feed feed{loop, fleet, "simulator"};
  std::vector<Sample> truth;
  AnkiCar* car = nullptr;

  Drive(sim::SensorModel sensor, int speed, double seconds, double offset = -23)
      : world(loop, sim::namedLayout("oval").value(), 1) {
    world.setSensor(sensor);
    feed.setTrack(world.track(), "layout");
    car = &testing::addSimulatedCar(loop, fleet, world,
                                    sim::CarSpec{.name = "skull", .offset_mm = offset});
    run(0.5);
    REQUIRE(car->sdkMode(true));
    REQUIRE(car->setSpeed(speed, 25000));
    std::function<void()> sample = [&] {
      auto t = world.cars()[0]->truth();
      truth.push_back({loop.seconds(), t.lap_distance_mm, t.laps});
      loop.after(std::chrono::milliseconds(1), sample);
    };
    loop.after(std::chrono::microseconds(500), sample);  // between the ticks' grid
    run(seconds);
  }
  void run(double seconds) {
    loop.at(loop.now() + fromSeconds(seconds), [this] { loop.stop(); });
    loop.run();
  }
  const std::deque<laps::LapTrace>& laps() const { return *feed.laps(car->identity().number); }

  // The largest distance between where a trace has the car at a time of its lap and where the
  // simulator had it at that time of the same lap (both timed from their own line crossing:
  // the link's latency delays every frame alike).
  double worstError(std::size_t& compared) const {
    double worst = 0;
    compared = 0;
    const auto& traces = laps();
    for (const auto& trace : traces) {
      // the simulator's crossing of the line that began this lap: its lap count went to lap
      auto begin = std::find_if(truth.begin(), truth.end(),
                                [&](const Sample& s) { return s.laps >= trace.lap; });
      auto end = std::find_if(truth.begin(), truth.end(),
                              [&](const Sample& s) { return s.laps >= trace.lap + 1; });
      if (begin == truth.end() || end == truth.end()) continue;
      // the crossing lies between the last sample before and the first after: take the middle
      const double start = begin == truth.begin() ? begin->t : (begin->t + (begin - 1)->t) / 2;
      for (auto s = begin; s != end; ++s) {
        const double at = trace.distanceAt(s->t - start);
        worst = std::max(worst, std::abs(at - s->distance));
        ++compared;
      }
    }
    return worst;
  }
};

}  // namespace

TEST_CASE("lap traces: where a lap puts the car is where the simulator had it") {
  SUBCASE("every code read: within a tick (7.5 mm at 1500 mm/s)") {
    Drive d(sim::SensorModel::Ideal, 1500, 20);
    REQUIRE(d.laps().size() >= 5);
    std::size_t compared = 0;
    const double worst = d.worstError(compared);
    CHECK(compared > 10000);
    MESSAGE("worst " << worst << " mm over " << compared << " samples");
    CHECK(worst <= 7.5 + 1.5);  // a tick, and the millisecond the samples are apart
    for (const auto& trace : d.laps()) {
      CHECK(trace.clean);
      CHECK(trace.everyPieceReported());
      CHECK(trace.points.front().distance == 0);
      CHECK(trace.points.back().distance == doctest::Approx(trace.length));
      CHECK(trace.points.back().t == doctest::Approx(trace.time));
    }
  }
  SUBCASE("as a real car reports (no position on the curves at speed): bounded") {
    Drive d(sim::SensorModel::Real, 1500, 20);
    REQUIRE(d.laps().size() >= 5);
    bool thinned = false;
    for (const auto& trace : d.laps()) thinned = thinned || !trace.everyPieceReported();
    CHECK(thinned);  // the test is about thinned laps
    std::size_t compared = 0;
    const double worst = d.worstError(compared);
    CHECK(compared > 10000);
    MESSAGE("worst " << worst << " mm over " << compared << " samples");
    // transitions are exact to a tick; between them the car moves at its speed
    CHECK(worst <= 7.5 + 1.5);
  }
}

TEST_CASE("lap traces: a lap's time is the tracker's, and each piece's entry is its transition") {
  Drive d(sim::SensorModel::Real, 900, 25, 23);
  const auto* tracker = d.feed.tracker(d.car->identity().number);
  REQUIRE(tracker);
  const auto& traces = d.laps();
  REQUIRE(traces.size() >= 3);
  REQUIRE(tracker->lapTimes().size() == traces.size());
  laps::LapMap map(d.world.track());
  for (std::size_t i = 0; i < traces.size(); ++i) {
    CHECK(traces[i].lap == static_cast<int>(i + 1));
    CHECK(traces[i].time == doctest::Approx(tracker->lapTimes()[i]));
    for (std::size_t k = 1; k < map.n; ++k) {
      CHECK(std::isfinite(traces[i].pieceEntered[k]));
      CHECK(traces[i].enteredAt(k, map) > traces[i].enteredAt(k - 1, map));
    }
  }
}
