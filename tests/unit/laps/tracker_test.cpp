// The view's lap counter and localization (engine/laps/tracker.cpp) under what real cars send
// (../shared/realdata): a transition (0x29) at every piece boundary, and position updates
// (0x27) that thin out with speed — on a curve at race speed usually none at all.
#include "engine/laps/tracker.hpp"

#include <doctest/doctest.h>

#include <random>

#include "engine/sim/track.hpp"

using namespace pitwall;

namespace {

// Drives `laps` laps of `track` from its first piece, a position update on each piece kept with
// chance `keep(piece index, lap)`, a transition at every boundary; time advances 1 s a piece.
template <class Keep>
laps::CarTracker drive(const sim::Track& track, const sim::Track* map, int laps, Keep keep) {
  laps::CarTracker tracker;
  tracker.setTrack(map);
  CarState state;
  double now = 0;
  const auto& pieces = track.pieces();
  for (int lap = 0; lap < laps; ++lap) {
    for (std::size_t i = 0; i < pieces.size(); ++i) {
      if (keep(i, lap)) {
        anki::PositionUpdate p;
        p.piece_id = pieces[i].id;
        p.location_id = 1;
        tracker.update(p, state, now + 0.5);
      }
      now += 1;
      tracker.update(anki::TransitionUpdate{}, state, now);
    }
  }
  return tracker;
}

}  // namespace

TEST_CASE("tracker: every lap counted with every position update, and with most of them lost") {
  auto oval = sim::loadLayout("oval");
  REQUIRE(oval);
  const sim::Track& track = *oval;
  const int kLaps = 12;
  // the car starts on the start piece's first half: the first crossing starts lap 1
  const auto full = drive(track, &track, kLaps, [](std::size_t, int) { return true; });
  const int expected = full.laps();
  CHECK(expected >= kLaps - 2);
  for (double t : full.lapTimes()) CHECK(t == doctest::Approx(track.size()));

  SUBCASE("with the map: one position update to localize, then transitions only") {
    auto thin =
        drive(track, &track, kLaps, [](std::size_t i, int lap) { return lap == 0 && i == 0; });
    CHECK(thin.laps() == expected);
    CHECK(thin.lapTimes() == full.lapTimes());
  }
  SUBCASE("with the map: any share of position updates lost, many seeds") {
    for (unsigned seed = 1; seed <= 50; ++seed) {
      std::mt19937 random(seed);
      const double lost = std::uniform_real_distribution<double>(0.25, 1.0)(random);
      auto thin = drive(track, &track, kLaps, [&](std::size_t i, int lap) {
        if (lap == 0 && i == 0) return true;  // localized once, where the full run starts
        return std::uniform_real_distribution<double>(0, 1)(random) >= lost;
      });
      CAPTURE(seed);
      CAPTURE(lost);
      CHECK(thin.laps() == expected);
    }
  }
  SUBCASE("without a map: the start piece seen for two laps, then no position update at all") {
    auto thin = drive(track, nullptr, kLaps, [&](std::size_t i, int lap) {
      return lap < 3 && track.pieces()[i].id == anki::kFinishBefore;
    });
    CHECK(thin.laps() == expected);
    CHECK(thin.lapTimes() == full.lapTimes());
  }
  SUBCASE("without a map: the start piece's updates lost at random after the first laps") {
    for (unsigned seed = 1; seed <= 50; ++seed) {
      std::mt19937 random(seed);
      auto thin = drive(track, nullptr, kLaps, [&](std::size_t, int lap) {
        return lap < 3 || std::uniform_real_distribution<double>(0, 1)(random) < 0.3;
      });
      CAPTURE(seed);
      CHECK(thin.laps() == expected);
    }
  }
}

TEST_CASE("tracker: without a map and without the start piece's reports no lap is invented") {
  auto oval = sim::loadLayout("oval");
  REQUIRE(oval);
  auto none = drive(*oval, nullptr, 6, [&](std::size_t i, int) {
    return oval->pieces()[i].id != anki::kFinishBefore &&
           oval->pieces()[i].id != anki::kFinishAfter;
  });
  CHECK(none.laps() == 0);
}

TEST_CASE(
    "tracker: between updates the car moves on by its speed along its lane, never past the "
    "piece's end") {
  const sim::Track track = sim::namedLayout("oval").value();
  laps::CarTracker tracker;
  tracker.setTrack(&track);
  CarState state;
  CHECK(tracker.fractionAt(5, 1000, 0, false) == 0);  // not localized: nothing to move on
  // a report on the start piece (34), then the transitions onto 33 and the straight after it
  anki::PositionUpdate p;
  p.piece_id = anki::kFinishBefore;
  p.location_id = 0;
  tracker.update(p, state, 1.0);
  tracker.update(anki::TransitionUpdate{}, state, 1.2);
  tracker.update(anki::TransitionUpdate{}, state, 1.4);
  REQUIRE(tracker.pieceIndex());
  const sim::Piece& straight = track.pieces()[*tracker.pieceIndex()];
  REQUIRE(straight.type == anki::PieceType::Straight);
  CHECK(tracker.fraction() == 0);
  CHECK(tracker.positionTime() == doctest::Approx(1.4));
  // 0.28 s at 1000 mm/s on a 560 mm straight: half of it
  CHECK(tracker.fractionAt(1.68, 1000, 23, false) == doctest::Approx(0.5));
  CHECK(tracker.fractionAt(1.4, 1000, 23, false) == 0);
  CHECK(tracker.fractionAt(9.0, 1000, 23, false) == 1);  // the transition says when it left
  CHECK(tracker.fractionAt(9.0, 0, 23, false) == 0);     // standing
  // onto the curve: on the outer lane of a left curve (+68 mm) it is longer than the centre's
  tracker.update(anki::TransitionUpdate{}, state, 2.0);
  const sim::Piece& curve = track.pieces()[*tracker.pieceIndex()];
  REQUIRE(curve.type == anki::PieceType::Curve);
  const double outer = curve.length(68);
  CHECK(outer > curve.length(0));
  CHECK(tracker.fractionAt(2.0 + 0.25 * outer / 800, 800, 68, false) == doctest::Approx(0.25));
}

TEST_CASE(
    "tracker: a car that pulls away from the grid without a report crosses the line on the "
    "transition it made before its first report") {
  const sim::Track track = sim::namedLayout("oval").value();
  CarState state;
  // off the grid (34) at speed: no report on 34, the line at t = 1, the first report on the
  // piece after the next one (two transitions back), then reports only on the start piece
  laps::CarTracker tracker;
  tracker.setTrack(&track);
  tracker.update(anki::TransitionUpdate{}, state, 1.0);  // 34 → 33: the line
  tracker.update(anki::TransitionUpdate{}, state, 1.2);  // 33 → straight
  anki::PositionUpdate p;
  p.piece_id = track.pieces()[2].id;
  p.location_id = 1;
  tracker.update(p, state, 1.3);
  REQUIRE(tracker.pieceIndex() == 2u);
  CHECK(tracker.laps() == 0);  // the line crossed starts lap 1
  // the rest of the lap by transitions alone: the line again at 1.0 + 9 pieces' time
  double now = 1.2;
  for (std::size_t i = 2; i < track.size(); ++i)
    tracker.update(anki::TransitionUpdate{}, state, now += 1);
  tracker.update(anki::TransitionUpdate{}, state, now += 1);  // 34 → 33
  CHECK(tracker.laps() == 1);
  REQUIRE(tracker.lapTimes().size() == 1);
  CHECK(tracker.lapTimes()[0] == doctest::Approx(now - 1.0));

  // a car whose first report shows it has not reached the line yet: nothing is crossed
  laps::CarTracker before;
  before.setTrack(&track);
  before.update(anki::TransitionUpdate{}, state, 1.0);
  p.piece_id = anki::kFinishBefore;
  before.update(p, state, 1.1);
  before.update(anki::TransitionUpdate{}, state, 1.5);  // now the line
  before.update(anki::TransitionUpdate{}, state, 2.5);
  for (int k = 1; k <= 8; ++k) before.update(anki::TransitionUpdate{}, state, 2.5 + k);
  CHECK(before.laps() == 1);
  CHECK(before.lapTimes()[0] == doctest::Approx(9.0));
}
