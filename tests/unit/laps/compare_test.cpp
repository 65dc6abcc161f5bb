// Laps compared (engine/laps/compare.cpp): two laps with a known difference — one slower in
// one curve only — give a delta that rises across that curve and is flat elsewhere, by distance
// when every piece reported its position and per piece when the curves sent none.
#include "engine/laps/compare.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <functional>

#include "engine/laps/compare_report.hpp"
#include "engine/laps/ghost.hpp"

using namespace pitwall;

namespace {

// A lap driven at speed(distance) mm/s: a point every 20 mm (a position update, where the piece
// reports), one at every boundary (a transition).
laps::LapTrace drive(const laps::LapMap& map, const std::function<double(double)>& speed,
                     const std::function<bool(std::size_t)>& reports) {
  laps::LapTrace lap;
  lap.lap = 1;
  lap.length = map.lap;
  lap.pieceEntered.assign(map.n, NAN);
  lap.pieceReported.assign(map.n, false);
  lap.points.push_back({0, 0, NAN, NAN});
  lap.pieceEntered[0] = 0;
  double t = 0, d = 0, next = 20;
  std::size_t k = 0;
  const double dt = 1e-4;
  while (d < map.lap) {
    d += speed(d) * dt;
    t += dt;
    while (k + 1 < map.n && d >= map.start[k + 1]) {
      ++k;
      lap.pieceEntered[k] = t;
      lap.points.push_back({t, map.start[k], NAN, NAN});
    }
    if (d >= next && d < map.lap) {
      if (reports(k)) {
        lap.pieceReported[k] = true;
        lap.points.push_back({t, d, speed(d), -23});
      }
      next += 20;
    }
  }
  lap.time = t;
  lap.points.push_back({t, map.lap, NAN, NAN});
  return lap;
}

}  // namespace

TEST_CASE("compare: one lap slower in one curve only") {
  const sim::Track track = sim::namedLayout("oval").value();
  const laps::LapMap map(track);
  const auto sections = laps::sections(track, map);
  // the oval from the line: 33 S:36 | L:17 L:18 | S:39 S:40 | L:20 L:23 | 34
  REQUIRE(sections.size() == 5);
  CHECK(sections[0].name == "straight 1");
  CHECK(sections[1].name == "left 1");
  CHECK(sections[1].curve);
  CHECK(sections[3].name == "left 2");
  CHECK(sections[4].to == doctest::Approx(map.lap));
  const laps::Section& slowCurve = sections[1];
  auto fast = [](double) { return 1000.0; };
  auto slow = [&](double d) { return d >= slowCurve.from && d < slowCurve.to ? 600.0 : 1000.0; };

  for (bool curvesReport : {true, false}) {
    CAPTURE(curvesReport);
    auto reports = [&](std::size_t k) {
      return curvesReport || track.piece(map.trackIndex(k)).turn == 0;
    };
    const auto a = drive(map, fast, reports);
    const auto b = drive(map, slow, reports);
    const auto c = laps::compare({&a, &b}, map, sections, 10);
    CHECK(c.byDistance == curvesReport);
    REQUIRE(c.delta.size() == 2);
    const double lost =
        slowCurve.to / 600 - slowCurve.to / 1000 - (slowCurve.from / 600 - slowCurve.from / 1000);
    CHECK(b.time - a.time == doctest::Approx(lost).epsilon(0.01));
    for (std::size_t i = 0; i < c.distance.size(); ++i) {
      const double at = c.distance[i];
      CAPTURE(at);
      CHECK(c.delta[0][i] == 0);
      if (at <= slowCurve.from) CHECK(std::abs(c.delta[1][i]) < 0.002);  // flat before
      if (at >= slowCurve.to) CHECK(c.delta[1][i] == doctest::Approx(lost).epsilon(0.01));
      if (i > 0 && at > slowCurve.from && at <= slowCurve.to)  // rising across it
        CHECK(c.delta[1][i] > c.delta[1][i - 1]);
    }
    // sections: only the slow curve differs
    for (std::size_t s = 0; s < sections.size(); ++s) {
      CAPTURE(sections[s].name);
      const double diff = c.sectionTimes[s][1] - c.sectionTimes[s][0];
      if (s == 1)
        CHECK(diff == doctest::Approx(lost).epsilon(0.01));
      else
        CHECK(std::abs(diff) < 0.002);
    }
    // what is told: the sentence says how the laps were aligned; the charts hold both laps
    laps::Report report{{{"A", &a}, {"B", &b}}, sections, c, "oval"};
    const std::string text = laps::reportText(report);
    CHECK(text.find(curvesReport ? "aligned by distance" : "per piece") != std::string::npos);
    CHECK(text.find("left 1") != std::string::npos);
    const std::string svg = laps::reportSvg(report);
    CHECK(svg.find("class=\"delta\"") != std::string::npos);
    CHECK(svg.find("<polyline class=\"lap\"") != std::string::npos);
    const auto json = laps::reportJson(report);
    CHECK(json["byDistance"] == curvesReport);
    CHECK(json["sections"][1]["name"] == "left 1");
  }
}

TEST_CASE("compare: a trace's time at a distance and distance at a time are inverse") {
  const sim::Track track = sim::namedLayout("kidney").value();
  const laps::LapMap map(track);
  const auto lap = drive(
      map, [](double d) { return 500 + 0.2 * d; }, [](std::size_t) { return true; });
  for (double d = 0; d <= map.lap; d += 37) {
    CAPTURE(d);
    CHECK(lap.distanceAt(lap.timeAt(d)) == doctest::Approx(d).epsilon(1e-6));
  }
  CHECK(lap.timeAt(-5) == 0);
  CHECK(lap.timeAt(map.lap + 100) == doctest::Approx(lap.time));
}

TEST_CASE("ghost lap: the lanes a record says are taken on the road") {
  laps::LapTrace t;
  t.time = 4;
  t.length = 4000;
  t.points = {{0, 0, NAN, NAN},
              {1, 1000, 600, -700},
              {2, 2000, 600, 1e38f},
              {3, 3000, 600, 23},
              {4, 4000, NAN, NAN}};
  const sim::GhostLap g = laps::ghostLap(t);
  REQUIRE(g.lanes.size() == 3);
  CHECK(g.lanes[0].offset == -70);
  CHECK(g.lanes[1].offset == 70);
  CHECK(g.lanes[2].offset == 23);
  CHECK(g.points.size() == 5);
  CHECK(g.distanceAt(2.5) == doctest::Approx(2500));
}
