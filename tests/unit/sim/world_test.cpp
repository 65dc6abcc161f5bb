// World rules: delocalization, lift/place, collisions, noise, determinism (docs/simulator.md).
#include <doctest/doctest.h>

#include <cmath>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include "engine/protocol/anki/codec.hpp"
#include "engine/sim/grid.hpp"
#include "engine/sim/world.hpp"

using namespace pitwall;
using namespace pitwall::sim;
using namespace std::chrono_literals;

namespace {

struct Heard {
  TimePoint t;
  std::size_t car;
  anki::Frame frame;
  anki::Message m;
};

// Cars on a track, each connected to a sink that logs its decoded frames with their time.
struct Rig {
  Loop loop{ClockKind::Virtual};
  World world;
  std::vector<SimCar*> cars;
  std::vector<Heard> heard;

  explicit Rig(std::uint64_t seed = 1, std::string_view layout = "oval")
      : world(loop, namedLayout(layout).value(), seed) {
    // the world's rules, frame by frame: every code, only real contacts (the real sensor
    // model has tests of its own, sensor_test.cpp, and the determinism test below)
    world.setSensor(SensorModel::Ideal);
  }
  SimCar& add(CarSpec spec) {
    SimCar& car = world.addCar(std::move(spec));
    std::size_t index = cars.size();
    cars.push_back(&car);
    car.connect(
        [this, index](std::span<const std::uint8_t> f) {
          anki::Frame frame;
          std::copy(f.begin(), f.end(), frame.bytes.begin());
          frame.length = static_cast<std::uint8_t>(f.size());
          heard.push_back({loop.now(), index, frame, anki::decode(f).value()});
        },
        [] {});
    send(car, anki::SdkMode{true, 1});
    return car;
  }
  void send(SimCar& car, const anki::Message& m) { car.receive(anki::encode(m).span()); }
  void runUntil(double seconds) {
    loop.at(fromSeconds(seconds), [this] { loop.stop(); });
    loop.run();
  }
  template <class T>
  std::vector<T> all(std::size_t car) const {
    std::vector<T> out;
    for (const auto& h : heard)
      if (auto* m = std::get_if<T>(&h.m); m && h.car == car) out.push_back(*m);
    return out;
  }
  template <class T>
  std::vector<TimePoint> times(std::size_t car) const {
    std::vector<TimePoint> out;
    for (const auto& h : heard)
      if (std::holds_alternative<T>(h.m) && h.car == car) out.push_back(h.t);
    return out;
  }
};

double aheadOf(const Rig& rig, const SimCar& rear, const SimCar& front) {
  double lap = rig.world.track().lapLength(0);
  double d = front.truth().lap_distance_mm - rear.truth().lap_distance_mm;
  return d < 0 ? d + lap : d;
}

}  // namespace

TEST_CASE("too fast for a curve's lane: the car delocalizes, coasts to a stop and goes quiet") {
  Rig rig;
  // Inner lane of the left curves (r = 212 mm): 1500²/212 ≈ 10600 mm/s² > 9000.
  SimCar& car = rig.add({.name = "car", .piece_index = 2, .offset_mm = -68});
  rig.send(car, anki::SetSpeed{1500, 25000});
  rig.runUntil(2);
  Truth t = car.truth();
  CHECK(t.delocalized);
  CHECK_FALSE(t.on_track);
  CHECK(t.speed_mm_s == 0);
  REQUIRE(rig.times<anki::Delocalized>(0).size() == 1);
  auto status = rig.all<anki::CarStatus>(0);
  CHECK_FALSE(status.back().on_track);
  // Thrown off as it entered curve 17, it stopped within 200 mm of the curve's start.
  CHECK(t.piece_id == 17);
  CHECK(t.piece_distance_mm < 200);
  // Nothing more after the delocalization frame: no positions, no transitions.
  TimePoint off = rig.times<anki::Delocalized>(0)[0];
  for (TimePoint p : rig.times<anki::PositionUpdate>(0)) CHECK(p <= off);
  for (TimePoint p : rig.times<anki::TransitionUpdate>(0)) CHECK(p <= off);
  auto laps = t.laps;
  rig.send(car, anki::SetSpeed{600, 25000});
  rig.runUntil(10);
  CHECK(car.truth().laps == laps);
  CHECK(car.truth().speed_mm_s == 0);
}

TEST_CASE("below the lateral limit the car holds its lane through every curve") {
  Rig rig;
  SimCar& inner = rig.add({.name = "inner", .piece_index = 2, .offset_mm = -68});
  rig.send(inner, anki::SetSpeed{1300, 25000});  // 1300²/212 ≈ 7970 mm/s²
  rig.runUntil(20);
  CHECK_FALSE(inner.truth().delocalized);
  CHECK(inner.truth().laps >= 6);
}

TEST_CASE("leaving the road delocalizes the car") {
  Rig rig;
  SimCar& car = rig.add({.name = "car", .piece_index = 2});
  rig.send(car, anki::SetSpeed{500, 25000});
  rig.send(car, anki::ChangeLane{300, 3000, 130.0f});
  rig.runUntil(3);
  CHECK(car.truth().delocalized);
  CHECK(car.truth().offset_mm > 100);
  CHECK(car.truth().offset_mm < 110);  // the lateral move stopped there
  CHECK(rig.times<anki::Delocalized>(0).size() == 1);
  CHECK(rig.all<anki::OffsetUpdate>(0).empty());
}

TEST_CASE("a lifted car delocalizes at once; placed back it is on track and stopped") {
  Rig rig;
  SimCar& car = rig.add({.name = "car", .piece_index = 2});
  rig.send(car, anki::SetSpeed{700, 25000});
  rig.runUntil(1);
  car.lift();
  CHECK(car.truth().delocalized);
  CHECK_FALSE(car.truth().on_track);
  CHECK(car.truth().speed_mm_s == 0);
  CHECK(rig.times<anki::Delocalized>(0).size() == 1);
  CHECK_FALSE(rig.all<anki::CarStatus>(0).back().on_track);
  auto quiet = rig.heard.size();
  rig.runUntil(3);
  CHECK(rig.heard.size() == quiet);

  car.place(5, 23);
  Truth t = car.truth();
  CHECK(t.on_track);
  CHECK_FALSE(t.delocalized);
  CHECK(t.piece_index == 5);
  CHECK(t.offset_mm == 23);
  CHECK(t.speed_mm_s == 0);
  CHECK(t.target_speed_mm_s == 0);
  CHECK(rig.all<anki::CarStatus>(0).back().on_track);
  rig.send(car, anki::SetSpeed{700, 25000});
  rig.runUntil(5);
  auto pos = rig.all<anki::PositionUpdate>(0);
  REQUIRE_FALSE(pos.empty());
  CHECK(pos.back().offset_mm == 23);
}

TEST_CASE("a faster car is held one car length behind the car ahead on its lane") {
  Rig rig;
  SimCar& rear = rig.add({.name = "rear", .piece_index = 2});
  SimCar& front = rig.add({.name = "front", .piece_index = 2, .distance_mm = 300, .offset_mm = 10});
  rig.send(front, anki::SetSpeed{300, 25000});
  rig.send(rear, anki::SetSpeed{800, 25000});
  double closest = 1e9;
  for (int i = 1; i <= 1000; ++i) {
    rig.runUntil(i * 0.01);
    closest = std::min(closest, aheadOf(rig, rear, front));
  }
  CHECK(closest >= 90 - 0.5);  // lane and centre lengths differ a little across boundaries
  CHECK(aheadOf(rig, rear, front) == doctest::Approx(90).epsilon(0.02));
  CHECK(rear.truth().speed_mm_s == 300);
  CHECK(rear.truth().target_speed_mm_s == 800);
  CHECK(rear.truth().collisions == 1);
  CHECK(front.truth().collisions == 1);
  auto hitRear = rig.all<anki::Collision>(0);
  auto hitFront = rig.all<anki::Collision>(1);
  REQUIRE(hitRear.size() == 1);
  REQUIRE(hitFront.size() == 1);
  CHECK(hitRear[0].side == 0);
  CHECK(hitRear[0].front_back == 1);
  CHECK(hitFront[0].front_back == 0);
  // Released, the rear car falls back; pushing again is a new contact.
  rig.send(rear, anki::SetSpeed{200, 25000});
  rig.runUntil(12);
  CHECK(aheadOf(rig, rear, front) > 150);
  rig.send(rear, anki::SetSpeed{800, 25000});
  rig.runUntil(16);
  CHECK(rear.truth().collisions == 2);
  CHECK(rig.all<anki::Collision>(1).size() == 2);
}

TEST_CASE("a car is held behind the car ahead across the finish line too") {
  Rig rig;
  SimCar& rear = rig.add({.name = "rear", .piece_index = 0, .distance_mm = 100});
  SimCar& front = rig.add({.name = "front", .piece_index = 1, .distance_mm = 50});
  CHECK(aheadOf(rig, rear, front) == doctest::Approx(290));
  rig.send(front, anki::SetSpeed{200, 25000});
  rig.send(rear, anki::SetSpeed{900, 25000});
  double closest = 1e9;
  for (int i = 1; i <= 300; ++i) {
    rig.runUntil(i * 0.01);
    closest = std::min(closest, aheadOf(rig, rear, front));
  }
  CHECK(closest >= 90 - 0.5);
  CHECK(rear.truth().collisions == 1);
  CHECK(rear.truth().speed_mm_s == 200);
}

TEST_CASE("a chain of cars settles one car length apart, each contact counted once") {
  Rig rig;
  SimCar& a = rig.add({.name = "a", .piece_index = 5});
  SimCar& b = rig.add({.name = "b", .piece_index = 5, .distance_mm = 200});
  SimCar& c = rig.add({.name = "c", .piece_index = 5, .distance_mm = 400, .offset_mm = -15});
  rig.send(c, anki::SetSpeed{250, 25000});
  rig.send(b, anki::SetSpeed{500, 25000});
  rig.send(a, anki::SetSpeed{900, 25000});
  rig.runUntil(6);
  CHECK(aheadOf(rig, a, b) == doctest::Approx(90).epsilon(0.02));
  CHECK(aheadOf(rig, b, c) == doctest::Approx(90).epsilon(0.02));
  CHECK(a.truth().speed_mm_s == 250);
  CHECK(b.truth().speed_mm_s == 250);
  CHECK(a.truth().collisions == 1);
  CHECK(b.truth().collisions == 2);
  CHECK(c.truth().collisions == 1);
}

TEST_CASE("cars on lanes 40 mm or more apart pass each other") {
  Rig rig;
  SimCar& fast = rig.add({.name = "fast", .piece_index = 2, .offset_mm = -23});
  SimCar& slow = rig.add({.name = "slow", .piece_index = 2, .distance_mm = 300, .offset_mm = 23});
  rig.send(slow, anki::SetSpeed{300, 25000});
  rig.send(fast, anki::SetSpeed{800, 25000});
  rig.runUntil(3);
  CHECK(fast.truth().lap_distance_mm > slow.truth().lap_distance_mm + 500);
  CHECK(fast.truth().collisions == 0);
  CHECK(rig.all<anki::Collision>(0).empty());
}

TEST_CASE("cars meeting head-on both stop where they touch") {
  Rig rig;
  SimCar& a = rig.add({.name = "a", .piece_index = 5});
  SimCar& b = rig.add({.name = "b", .piece_index = 5, .distance_mm = 400});
  rig.send(b, anki::Turn{anki::TurnType::UTurn, anki::TurnTrigger::Immediate});
  rig.send(a, anki::SetSpeed{400, 25000});
  rig.send(b, anki::SetSpeed{400, 25000});
  rig.runUntil(2);
  CHECK(b.truth().lap_distance_mm - a.truth().lap_distance_mm >= 90 - 1e-6);
  CHECK(a.truth().speed_mm_s == 0);
  CHECK(b.truth().speed_mm_s == 0);
  CHECK(a.truth().collisions == 1);
  CHECK(b.truth().collisions == 1);
  REQUIRE(rig.all<anki::Collision>(0).size() == 1);
  REQUIRE(rig.all<anki::Collision>(1).size() == 1);
  CHECK(rig.all<anki::Collision>(1)[0].front_back == 1);
}

TEST_CASE("laps count finish lines crossed forward, and lap distance runs from piece 33") {
  Rig rig;
  SimCar& car = rig.add({.name = "car", .piece_index = 0, .distance_mm = 100});
  CHECK(car.truth().lap_distance_mm == doctest::Approx(rig.world.track().lapLength(0) - 240));
  rig.send(car, anki::SetSpeed{1000, 25000});
  rig.runUntil(0.3);
  CHECK(car.truth().laps == 1);
  CHECK(car.truth().piece_id == 33);
  CHECK(car.truth().lap_distance_mm < 70);
}

TEST_CASE("the world ticks only while a car has something to do") {
  Rig rig;
  SimCar& car = rig.add({.name = "car", .piece_index = 2});
  rig.send(car, anki::SetSpeed{500, 25000});
  rig.loop.at(fromSeconds(2), [&] { rig.send(car, anki::SetSpeed{0, 5000}); });
  rig.loop.run();  // ends by itself once the car has stopped
  CHECK(rig.loop.seconds() == doctest::Approx(2.1).epsilon(0.01));
  CHECK(car.truth().speed_mm_s == 0);
  CHECK(rig.loop.pendingTimers() == 0);
}

TEST_CASE("dropped frames come close to the asked rate and repeat with the same seed") {
  auto run = [](std::uint64_t seed) {
    Rig rig(seed);
    SimCar& car = rig.add({});
    rig.world.setNoise({.drop = 0.25});
    rig.heard.clear();
    std::vector<bool> got;
    for (int i = 0; i < 4000; ++i) {
      auto before = rig.heard.size();
      rig.send(car, anki::PingRequest{});
      got.push_back(rig.heard.size() > before);
    }
    return got;
  };
  auto a = run(11);
  auto b = run(11);
  auto c = run(12);
  long kept = std::count(a.begin(), a.end(), true);
  CHECK(kept > 3000 - 150);
  CHECK(kept < 3000 + 150);
  CHECK(a == b);
  CHECK(a != c);
}

TEST_CASE("late frames are delayed by at most late_by and never overtake each other") {
  Rig rig(5);
  SimCar& car = rig.add({});
  rig.world.setNoise({.late = 0.3, .late_by = 100ms});
  rig.heard.clear();
  std::vector<anki::Message> asked = {anki::PingRequest{}, anki::VersionRequest{},
                                      anki::BatteryRequest{}};
  std::vector<std::pair<TimePoint, std::size_t>> sent;
  for (int i = 0; i < 600; ++i) {
    TimePoint at = i * 10ms;
    rig.loop.at(at, [&, i, at] {
      rig.send(car, asked[i % 3]);
      sent.emplace_back(at, i % 3);
    });
  }
  rig.runUntil(8);
  REQUIRE(rig.heard.size() == sent.size());
  Duration longest{0};
  int delayed = 0;
  for (std::size_t i = 0; i < sent.size(); ++i) {
    CHECK(
        rig.heard[i].m.index() ==
        (std::vector<std::size_t>{anki::Message(anki::PingResponse{}).index(),
                                  anki::Message(anki::VersionResponse{}).index(),
                                  anki::Message(anki::BatteryResponse{}).index()})[sent[i].second]);
    Duration d = rig.heard[i].t - sent[i].first;
    CHECK(d >= Duration::zero());
    longest = std::max(longest, d);
    delayed += d > Duration::zero();
  }
  CHECK(longest <= 100ms);
  CHECK(delayed > 150);  // 30 % late, and frames queued behind them wait too
}

TEST_CASE("the same seed and commands give the same frames at the same times") {
  auto run = [](std::uint64_t seed) {
    Rig rig(seed, "kidney");
    rig.world.setNoise({.drop = 0.05, .late = 0.1, .late_by = 80ms});
    rig.world.setSensor(SensorModel::Real);  // its draws too
    SimCar& a = rig.add({.name = "a", .piece_index = 0});
    SimCar& b = rig.add({.name = "b", .piece_index = 3, .offset_mm = 23});
    SimCar& c = rig.add({.name = "c", .piece_index = 6, .offset_mm = -68});
    rig.send(a, anki::SetSpeed{900, 3000});
    rig.send(b, anki::SetSpeed{600, 1000});
    rig.send(c, anki::SetSpeed{1100, 25000});
    rig.loop.at(fromSeconds(3), [&] { rig.send(a, anki::ChangeLane{200, 2000, 23.0f}); });
    rig.loop.at(fromSeconds(7), [&] { rig.send(b, anki::SetSpeed{1200, 800}); });
    rig.runUntil(60);
    std::vector<std::tuple<TimePoint, std::size_t, anki::Frame>> log;
    for (auto& h : rig.heard) log.emplace_back(h.t, h.car, h.frame);
    return log;
  };
  auto first = run(99);
  auto second = run(99);
  CHECK(first.size() > 500);
  CHECK(first == second);
  CHECK(first != run(100));
}

// The starting grid (docs/simulator.md "The grid"): four cars on each piece. Slot 36 on the
// 9-piece oval would stand on slot 0, so a run with more cars races on ovalLayoutFor(N).
TEST_CASE("a grid holds four cars per piece; ovalLayoutFor(N) is the smallest oval that holds N") {
  Track oval = namedLayout("oval").value();
  CHECK(gridCapacity(oval) == 36);
  CHECK(gridSpec(oval, 36).piece_index == gridSpec(oval, 0).piece_index);  // the wrap
  CHECK(gridSpec(oval, 36).offset_mm == gridSpec(oval, 0).offset_mm);
  CHECK(parseLayout(ovalLayoutFor(36)).value().size() == oval.size());  // the oval itself
  for (int n : {1, 4, 36, 37, 40, 41, 64, 100, 999, 1000}) {
    CAPTURE(n);
    Track track = parseLayout(ovalLayoutFor(n)).value();  // closes
    CHECK(gridCapacity(track) >= n);
    if (n > 36) CHECK(gridCapacity(track) - n < 8);  // one pair of straights more would be 8 cars
  }
}

TEST_CASE("1000 cars on the grid of ovalLayoutFor(1000) drive off without touching") {
  Loop loop{ClockKind::Virtual};
  Track track = parseLayout(ovalLayoutFor(1000)).value();
  World world(loop, track, 1);
  std::vector<SimCar*> cars;
  std::set<std::pair<std::size_t, double>> slots;
  for (int i = 0; i < 1000; ++i) {
    CarSpec spec = gridSpec(track, i);
    slots.emplace(spec.piece_index, spec.offset_mm);
    SimCar& car = world.addCar(std::move(spec));
    car.connect([](std::span<const std::uint8_t>) {}, [] {});
    car.receive(anki::encode(anki::SdkMode{true, 1}).span());
    car.receive(anki::encode(anki::SetSpeed{600, 25000}).span());
    cars.push_back(&car);
  }
  CHECK(slots.size() == 1000);  // every car on a place of its own
  loop.at(10s, [&] { loop.stop(); });
  loop.run();
  int collisions = 0, atSpeed = 0;
  for (SimCar* car : cars) {
    collisions += car->truth().collisions;
    atSpeed += car->truth().speed_mm_s == 600 ? 1 : 0;
  }
  CHECK(collisions == 0);
  CHECK(atSpeed == 1000);
}

// Real cars do not wait for the engine: when a long callback holds the loop, a simulated car on
// the real clock moves on by the wall clock too (the ticks it missed are made up at once), as a
// real one would have driven on meanwhile. The adversary holds the loop 400 ms in one callback.
TEST_CASE("real time: a car moves on by the wall clock while the loop is held") {
  Loop loop(ClockKind::Real);
  World world(loop, namedLayout("oval").value(), 1);
  SimCar& car = world.addCar({.name = "car", .piece_index = 2, .offset_mm = 0});
  car.connect([](std::span<const std::uint8_t>) {}, [] {});
  car.receive(anki::encode(anki::SdkMode{true, 1}).span());
  car.receive(anki::encode(anki::SetSpeed{400, 25000}).span());
  double before = 0, after = 0;
  TimePoint heldFrom{0}, heldUntil{0};
  // at full speed (reached within 20 ms at 25000 mm/s²), the loop held 400 ms
  loop.after(300ms, [&] {
    before = car.truth().lap_distance_mm;
    heldFrom = loop.now();
    std::this_thread::sleep_for(400ms);
    heldUntil = loop.now();
  });
  // the first tick after the hold, and nothing else in between
  loop.after(301ms, [&] {
    loop.after(6ms, [&] {
      after = car.truth().lap_distance_mm;
      loop.stop();
    });
  });
  auto guard = loop.after(20s, [&] { loop.stop(); });
  loop.run();
  loop.cancel(guard);
  const double held = toSeconds(heldUntil - heldFrom);
  REQUIRE(held >= 0.4);
  double moved = after - before;
  if (moved < 0) moved += world.track().lapLength(0);
  // the distance of the time held (and the few ms after), not the one or two ticks of the old
  // way (which made the simulation fall behind the wall clock)
  CHECK(moved >= 400 * held * 0.9);
  CHECK(world.lateTicks() >= 70);
}

TEST_CASE("virtual time: no tick is ever late") {
  Rig rig;
  SimCar& car = rig.add({.name = "car", .piece_index = 2});
  rig.send(car, anki::SetSpeed{800, 25000});
  rig.runUntil(5);
  CHECK(rig.world.lateTicks() == 0);
}
