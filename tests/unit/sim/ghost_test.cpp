// The simulator's ghost (docs/simulator.md "Ghosts", engine/sim/sim_car.cpp planGhost): a car
// that drives a recorded lap again, lap after lap, in the recorded time within a tick; that no
// car touches; that takes no lane change; that stands until a set-speed above 0 and stops on 0.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "engine/protocol/anki/codec.hpp"
#include "engine/sim/world.hpp"

using namespace pitwall;
using namespace pitwall::sim;

namespace {

struct Rig {
  Loop loop{ClockKind::Virtual};
  World world{loop, namedLayout("oval").value(), 1};
  std::vector<double> crossings;  // when the ghost's laps count went up (engine s)
  std::vector<std::size_t> collisions;
  SimCar* ghost = nullptr;

  void send(SimCar& car, const anki::Message& m) { car.receive(anki::encode(m).span()); }
  SimCar& connect(SimCar& car) {
    car.connect([](std::span<const std::uint8_t>) {}, [] {});
    send(car, anki::SdkMode{true, 1});
    return car;
  }
  void run(double seconds) {
    const double end = loop.seconds() + seconds;
    while (loop.seconds() < end - 1e-9) {  // the truth every millisecond
      loop.at(loop.now() + fromSeconds(0.001), [this] { loop.stop(); });
      loop.run();
      const int laps = ghost->truth().laps;
      if (laps > static_cast<int>(crossings.size())) crossings.push_back(loop.seconds());
    }
  }
};

// A lap of the oval at `slow` mm/s in its first curve pair and `fast` elsewhere (centre line).
std::shared_ptr<GhostLap> lapOf(const Track& track, double fast, double slow) {
  auto g = std::make_shared<GhostLap>();
  const std::size_t n = track.size(), finish = track.finishIndex();
  double d = 0, t = 0;
  g->points.push_back({0, 0});
  int curves = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const Piece& p = track.piece((finish + k) % n);
    const double len = p.length(0);
    const bool slowHere = p.turn != 0 && curves++ < 2;
    d += len;
    t += len / (slowHere ? slow : fast);
    g->points.push_back({t, d});
  }
  g->time = t;
  g->length = d;
  g->lanes.push_back({0, -23});
  return g;
}

}  // namespace

TEST_CASE("sim ghost: laps in the recorded time within a tick, touching no one") {
  Rig r;
  const auto lap = lapOf(r.world.track(), 1200, 500);
  CarSpec spec{.name = "ghost", .piece_index = r.world.track().finishIndex(), .offset_mm = -23};
  spec.ghost = lap;
  r.ghost = &r.connect(r.world.addCar(spec));
  // a car standing in its lane on the straight ahead of it, and one in front of it on the grid
  SimCar& blocker = r.connect(r.world.addCar(CarSpec{
      .name = "blocker", .piece_index = r.world.track().finishIndex() + 1, .offset_mm = -23}));
  CHECK(r.ghost->truth().ghost);
  CHECK_FALSE(blocker.truth().ghost);
  const double blockerAt = blocker.truth().lap_distance_mm;

  r.run(1);
  CHECK(r.ghost->truth().lap_distance_mm == 0);  // it stands until told to go
  const double go = r.loop.seconds();
  r.send(*r.ghost, anki::SetSpeed{300, 100});  // any speed above 0: go, at the lap's own pace
  r.send(*r.ghost, anki::ChangeLane{400, 4000, 60});  // taken by no ghost
  r.run(4 * lap->time + 0.5);
  REQUIRE(r.crossings.size() == 4);
  // each lap in the recorded time, within a tick (5 ms) and the millisecond the truth is read at
  double before = go;
  for (double at : r.crossings) {
    CHECK(std::abs(at - before - lap->time) < 0.006);
    before = at;
  }
  CHECK(std::abs(r.crossings.back() - go - 4 * lap->time) < 0.006);  // no drift over laps
  CHECK(r.ghost->truth().offset_mm == -23);
  CHECK(r.ghost->truth().collisions == 0);
  CHECK(blocker.truth().collisions == 0);
  CHECK(blocker.truth().lap_distance_mm == blockerAt);  // never pushed

  // speed 0: it stops where it is; a set-speed above 0 again: on from there
  r.send(*r.ghost, anki::SetSpeed{0, 1000});
  r.run(0.1);
  const double stoppedAt = r.ghost->truth().lap_distance_mm;
  r.run(1);
  CHECK(r.ghost->truth().lap_distance_mm == stoppedAt);
  CHECK(r.ghost->truth().speed_mm_s == 0);
  r.send(*r.ghost, anki::SetSpeed{800, 1000});
  r.run(0.2);
  CHECK(r.ghost->truth().lap_distance_mm > stoppedAt);
}

TEST_CASE("sim ghost: a lap faster than any car is driven at the top speed, not in a blink") {
  // a record's times are any numbers: a lap of a millisecond would be a million pieces a tick
  Rig r;
  const auto lap = lapOf(r.world.track(), 4e6, 4e6);  // ≈ 1 ms for the lap
  CarSpec spec{.name = "ghost", .piece_index = r.world.track().finishIndex(), .offset_mm = -23};
  spec.ghost = lap;
  r.ghost = &r.connect(r.world.addCar(spec));
  r.send(*r.ghost, anki::SetSpeed{300, 100});
  r.run(1);
  const auto t = r.ghost->truth();
  const double lapMm = lap->length;
  const double driven = t.laps * lapMm + t.lap_distance_mm;
  CHECK(driven <= GhostLap::kMaxSpeed * 1.0 + 1);
  CHECK(driven >= GhostLap::kMaxSpeed * 0.9);
}
