// The view's feed against the simulator's ground truth: a real World, real SimLinks, the real
// codec and car model; the feed's placement of every car, its laps, the event log, the race
// reported by a script's side, and the fleet's other observers kept.
#include <doctest/doctest.h>

#include <cmath>

#include "engine/core/log.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/sim/world.hpp"
#include "engine/view/feed.hpp"
#include "engine/view/geometry.hpp"
#include "tests/support/sim_cars.hpp"

using namespace pitwall;

namespace {

struct Race {
  Loop loop{ClockKind::Virtual};
  sim::World world;
  Fleet fleet{loop};
  std::unique_ptr<view::Feed> feed;
  explicit Race(sim::Track track = sim::namedLayout("oval").value())
      : world(loop, std::move(track), 1) {
    // as real cars report: no position update on most curves at speed (docs/simulator.md)
    world.setSensor(sim::SensorModel::Real);
  }
  void run(double seconds) {
    loop.at(loop.now() + fromSeconds(seconds), [this] { loop.stop(); });
    loop.run();
  }
  // A feed on the layout and one car, "skull", driving at `speed`.
  AnkiCar& driving(int speed, int accel) {
    feed = std::make_unique<view::Feed>(loop, fleet, "simulator");
    feed->setTrack(world.track(), "layout");
    auto& car = testing::addSimulatedCar(loop, fleet, world, sim::CarSpec{.name = "skull"});
    run(0.5);
    REQUIRE(car.sdkMode(true));
    REQUIRE(car.setSpeed(speed, accel));
    return car;
  }
};

}  // namespace

TEST_CASE("view feed: cars are placed where the simulator has them, and laps are counted") {
  // the named layouts, and one whose pieces all share two ids (matched along the driving order)
  std::vector<sim::Track> tracks;
  for (const auto& name : sim::layoutNames()) tracks.push_back(sim::namedLayout(name).value());
  tracks.push_back(
      sim::parseLayout("start S:36 L:17 L:17 S:36 S:36 L:17 L:17", "same ids").value());
  for (const auto& track : tracks) {
    CAPTURE(track.name());
    Race r(track);
    r.feed = std::make_unique<view::Feed>(r.loop, r.fleet, "simulator");
    r.feed->setTrack(r.world.track(), "layout");
    sim::CarSpec a{.name = "a", .piece_index = 0, .offset_mm = -68};
    sim::CarSpec b{.name = "b", .piece_index = 0, .offset_mm = 68};
    auto& ca = testing::addSimulatedCar(r.loop, r.fleet, r.world, a);
    auto& cb = testing::addSimulatedCar(r.loop, r.fleet, r.world, b);
    r.run(0.5);
    REQUIRE(ca.sdkMode(true));
    REQUIRE(cb.sdkMode(true));
    REQUIRE(ca.setSpeed(700, 2000));
    REQUIRE(cb.setSpeed(1000, 2000));
    int checked = 0;
    for (int step = 0; step < 300; ++step) {  // 30 s, looked at every 0.1 s
      r.run(0.1);
      auto state = r.feed->state();
      for (std::size_t k = 0; k < 2; ++k) {
        const auto& car = state["cars"][k];
        auto truth = r.world.cars()[k]->truth();
        if (car["x"].is_null()) continue;
        // the feed's piece is the simulator's (ids repeat on a track: matched along the order)
        // (or the piece before, when the car crossed into this one since its last report)
        const std::size_t n = r.world.track().size();
        const auto index = car["pieceIndex"].get<std::size_t>();
        const bool justCrossed =
            truth.piece_distance_mm < 30 && (index + 1) % n == truth.piece_index;
        CHECK((index == truth.piece_index || justCrossed));
        const auto& piece = r.world.track().piece(truth.piece_index);
        view::Pose real = view::pointOnTrack(
            r.world.track(), truth.piece_index,
            truth.piece_distance_mm / piece.length(truth.offset_mm), truth.offset_mm);
        // within the spacing of the location codes, and on the road
        CHECK(std::hypot(car["x"].get<double>() - real.x, car["y"].get<double>() - real.y) < 200);
        ++checked;
      }
    }
    CHECK(checked > 400);
    auto state = r.feed->state();
    for (std::size_t k = 0; k < 2; ++k) {
      auto truth = r.world.cars()[k]->truth();
      // the first crossing starts lap 1
      CHECK(state["cars"][k]["lap"].get<int>() == truth.laps - 1);
      CHECK(truth.laps >= 3);
      for (double t : state["cars"][k]["lapTimes"]) CHECK(t > 2.0);
      // a speed sample a frame, at most ten a second; at 700–1000 mm/s a real car's frames
      // that carry a speed (position updates) thin out to two or three a second
      CHECK(state["cars"][k]["speedHistory"].size() > 50);
    }
  }
}

TEST_CASE("view feed: connections and log lines join the event log; others' hooks still run") {
  Race r;
  int framesSeen = 0;
  auto counting =
      r.fleet.frames.connect([&](AnkiCar&, AnkiCar::Direction, std::span<const std::uint8_t>,
                                 const anki::Message&) { ++framesSeen; });
  r.feed = std::make_unique<view::Feed>(r.loop, r.fleet, "simulator");
  r.feed->followLog(true);
  auto& car = testing::addSimulatedCar(r.loop, r.fleet, r.world, sim::CarSpec{.name = "skull"});
  r.run(0.5);
  (void)car.sdkMode(true);
  r.run(0.2);
  CHECK(framesSeen > 0);
  pitwall::log::warn("race", "something to see");
  pitwall::log::info("quiet", "not for the view");
  auto state = r.feed->state();
  std::vector<std::string> texts;
  for (const auto& e : state["events"]) texts.push_back(e["text"]);
  CHECK(std::find(texts.begin(), texts.end(), "car 1 (skull) connected") != texts.end());
  CHECK(std::find(texts.begin(), texts.end(), "race: something to see") != texts.end());
  CHECK(std::find(texts.begin(), texts.end(), "quiet: not for the view") == texts.end());
  // the car's link as car.link has it: one connection, no drop yet
  auto link = state["cars"][0]["link"];
  CHECK(link["connects"] == 1);
  CHECK(link["drops"] == 0);
  CHECK(link["lastDrop"].is_null());
  CHECK(link["rssi"].is_null());  // the simulator's link tells none
  // updates carry only new events
  std::uint64_t cursor = 0, track = 0;
  CHECK(r.feed->update(cursor, track)["events"].size() == texts.size());
  CHECK(r.feed->update(cursor, track)["events"].empty());
  r.feed->event("info", "one more");
  CHECK(r.feed->update(cursor, track)["events"].size() == 1);
  // the log keeps its last 200 lines, not more
  for (int i = 0; i < 1000; ++i) r.feed->event("info", std::to_string(i));
  CHECK(r.feed->state()["events"].size() == 200);
  CHECK(r.feed->state()["events"].back()["text"] == "999");
  // the feed gone, the fleet's hooks are the ones from before
  r.feed.reset();
  int before = framesSeen;
  (void)car.ping();
  r.run(0.2);
  CHECK(framesSeen > before);
}

TEST_CASE("view feed: the race as reported; phases are logged; the track only when it changed") {
  Race r;
  r.feed = std::make_unique<view::Feed>(r.loop, r.fleet, "ble");
  // a browser had the track (none) with the state: updates leave it out until it changes
  std::uint64_t cursor = 0, seen = r.feed->trackVersion();
  CHECK(r.feed->state()["track"].is_null());
  CHECK_FALSE(r.feed->update(cursor, seen).contains("track"));
  r.feed->setTrack(r.world.track(), "scan");
  auto next = r.feed->update(cursor, seen);
  REQUIRE(next.contains("track"));
  CHECK(next["track"]["source"] == "scan");
  r.feed->setRace({{"title", "GP"}, {"phase", "grid"}});
  r.feed->setRace({{"title", "GP"}, {"phase", "grid"}, {"rows", nlohmann::json::array()}});
  r.feed->setRace({{"title", "GP"}, {"phase", "lights"}, {"light", 3}});
  auto state = r.feed->state();
  CHECK(state["race"]["light"] == 3);
  int phases = 0;
  for (const auto& e : state["events"]) phases += e["text"].get<std::string>().starts_with("GP: ");
  CHECK(phases == 2);  // grid once, lights once
}

TEST_CASE("view feed: a car lifted off the track is shown as such, and placed again when back") {
  Race r;
  auto& car = r.driving(600, 2000);
  r.run(3);
  auto placed = r.feed->state()["cars"][0];
  CHECK_FALSE(placed["x"].is_null());
  CHECK(placed["delocalized"] == false);
  r.world.cars()[0]->lift();
  r.run(0.5);
  auto lifted = r.feed->state()["cars"][0];
  CHECK(lifted["delocalized"] == true);
  CHECK(lifted["x"].is_null());  // not drawn where it was: the page lists it as off the track
  CHECK(lifted["pieceIndex"].is_null());
  r.world.cars()[0]->place(4, 0);
  REQUIRE(car.setSpeed(600, 2000));
  r.run(3);
  auto back = r.feed->state()["cars"][0];
  CHECK(back["delocalized"] == false);
  CHECK_FALSE(back["x"].is_null());
}

TEST_CASE("view feed: a long session's updates carry the latest laps, not all of them") {
  Race r;
  r.driving(1400, 5000);
  r.run(500);  // ≈ 170 laps
  const auto* tracker = r.feed->tracker(1);
  REQUIRE(tracker);
  const int laps = tracker->laps();
  REQUIRE(laps > 120);
  std::uint64_t cursor = 0, seen = 0;
  auto update = r.feed->update(cursor, seen)["cars"][0];
  CHECK(update["lap"] == laps);
  CHECK(update["lapTimes"].size() == 100);
  CHECK(update["lapTimesFrom"] == laps - 99);
  CHECK(update["lapTimes"].back().get<double>() ==
        doctest::Approx(tracker->lapTimes().back()).epsilon(1e-6));
  CHECK(update["bestLap"].get<double>() == doctest::Approx(*tracker->bestLap()).epsilon(1e-6));
  auto state = r.feed->state()["cars"][0];
  CHECK(state["lapTimes"].size() == static_cast<std::size_t>(laps));  // ≤ 1000: all of them
  CHECK(state["lapTimesFrom"] == 1);
  // the text the server sends is the same update
  cursor = 0, seen = 0;
  auto text = nlohmann::json::parse(r.feed->updateText(cursor, seen));
  CHECK(text["type"] == "update");
  CHECK(text["cars"][0]["lapTimes"] == update["lapTimes"]);
  CHECK(text.contains("track"));
  CHECK_FALSE(nlohmann::json::parse(r.feed->updateText(cursor, seen)).contains("track"));
}

TEST_CASE(
    "view feed: a car told to stop is shown at 0 mm/s once it falls silent, in the chart too") {
  Race r;
  auto& car = r.driving(600, 2000);
  r.run(3);
  r.feed->settle();
  CHECK(r.feed->state()["cars"][0]["speed"].get<int>() > 400);
  REQUIRE(car.setSpeed(0, 3000));
  r.run(2);  // stopped, and silent since (a real car reports nothing while it stands)
  CHECK(car.state().speed_mm_s > 0);  // the last report, kept by the model
  const auto changes = r.feed->changes();
  r.feed->settle();
  CHECK(r.feed->changes() > changes);  // an update is due
  auto stopped = r.feed->state()["cars"][0];
  CHECK(stopped["speed"] == 0);
  CHECK(stopped["speedHistory"].back()[1] == 0);
  std::uint64_t cursor = 0, seen = 0;
  CHECK(nlohmann::json::parse(r.feed->updateText(cursor, seen))["cars"][0]["speed"] == 0);
  // driving again: its reported speed
  REQUIRE(car.setSpeed(700, 2000));
  r.run(2);
  r.feed->settle();
  CHECK(r.feed->state()["cars"][0]["speed"].get<int>() > 400);
}

TEST_CASE("view feed: the view's ghost drives the personal best from the leader's crossing") {
  Race r;
  AnkiCar& car = r.driving(700, 2000);
  const laps::LapMap map(r.world.track());
  // a personal best at 1000 mm/s all the way round, in the inside lane
  laps::LapTrace best;
  best.lap = 1;
  best.time = map.lap / 1000;
  best.length = map.lap;
  best.points = {{0, 0, 1000, -68}, {best.time, map.lap, 1000, -68}};
  r.feed->setPersonalBest(best, "ann's personal best in skull");
  CHECK(r.feed->state()["viewGhost"].is_null());  // no crossing yet: nothing to start from
  double t0 = -1;
  for (int step = 0; step < 400 && t0 < 0; ++step) {
    r.run(0.05);
    auto g = r.feed->state()["viewGhost"];
    if (!g.is_null()) t0 = r.loop.seconds() - g["t"].get<double>();
  }
  REQUIRE(t0 >= 0);
  auto lastCrossing = r.feed->tracker(car.identity().number)->lastCrossing();
  REQUIRE(lastCrossing);
  CHECK(t0 == doctest::Approx(*lastCrossing).epsilon(0.001));
  // 1 s into the lap it is 1000 mm along it, where the geometry puts that point of the lap
  r.run(1.0 - (r.loop.seconds() - t0));
  auto s = r.feed->state();
  auto g = s["viewGhost"];
  REQUIRE_FALSE(g.is_null());
  CHECK(g["follows"] == car.identity().number);
  CHECK(g["label"] == "ann's personal best in skull");
  const double d = g["t"].get<double>() * 1000;
  std::size_t k = 0;
  while (k + 1 < map.n && d >= map.start[k + 1]) ++k;
  CHECK(g["pieceIndex"] == map.trackIndex(k));
  CHECK(g["fraction"].get<double>() ==
        doctest::Approx((d - map.start[k]) / map.length[k]).epsilon(0.01));
  CHECK(g["offset"] == -68);
  CHECK(g["speed"].get<double>() == doctest::Approx(1000).epsilon(0.01));
  auto pose = view::pointOnTrack(r.world.track(), g["pieceIndex"], g["fraction"], -68);
  CHECK(g["x"].get<double>() == doctest::Approx(pose.x).epsilon(0.01));
  // car 1 at 700 mm/s is behind it, against it by name
  CHECK(s["cars"][0]["deltaTo"] == "ann's personal best in skull");
  CHECK(s["cars"][0]["delta"].get<double>() > 0.2);
  // its lap done before the car's, it waits at the line
  r.run(best.time);
  g = r.feed->state()["viewGhost"];
  REQUIRE(r.feed->tracker(car.identity().number)->lastCrossing() == lastCrossing);  // (5.7 s a lap)
  CHECK(g["t"].get<double>() == doctest::Approx(best.time).epsilon(0.001));
  CHECK(g["speed"] == 0);
  // a new track forgets it
  r.feed->setTrack(r.world.track(), "layout");
  CHECK(r.feed->state()["viewGhost"].is_null());
}
