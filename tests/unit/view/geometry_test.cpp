// The track as drawn (engine/view/geometry): pieces meet, lanes lie where they should, a layout
// closes, the JSON and the SVG carry what the page and `pitwall track show` need.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "engine/sim/track.hpp"
#include "engine/view/geometry.hpp"

using namespace pitwall;
using namespace pitwall::view;

namespace {
double dist(const Pose& a, const Pose& b) {
  return std::hypot(a.x - b.x, a.y - b.y);
}
}  // namespace

TEST_CASE("view geometry: every named layout's pieces meet, lane by lane, and the lap closes") {
  std::vector<std::string> layouts = sim::layoutNames();
  // and a track of custom pieces: 45° curves of 400 mm, 200 mm hairpins, straights of its own
  layouts.push_back(
      "start S:60,len=440 L:61,r=400,deg=45 L:61,r=400,deg=45 L:61,r=400,deg=45 "
      "L:61,r=400,deg=45 S:60,len=440 S L:62,r=200,deg=90 S:64,len=400 L:62,r=200,deg=90");
  for (const auto& name : layouts) {
    CAPTURE(name);
    auto track =
        (name.find(' ') == std::string::npos ? sim::namedLayout(name) : sim::parseLayout(name))
            .value();
    for (double o : {-68.0, 0.0, 68.0}) {
      for (std::size_t i = 0; i < track.size(); ++i) {
        Pose end = pointOnTrack(track, i, 1.0, o);
        Pose next = pointOnTrack(track, (i + 1) % track.size(), 0.0, o);
        CHECK(dist(end, next) < 0.01);
        CHECK(std::abs(std::fmod(end.heading - next.heading + 360, 360.0)) < 1e-6);
      }
      // A lane's length along the drawing is the simulator's lap length for that lane.
      double drawn = 0;
      for (std::size_t i = 0; i < track.size(); ++i)
        for (int k = 0; k < 100; ++k)
          drawn += dist(pointOnTrack(track, i, k / 100.0, o),
                        pointOnTrack(track, i, (k + 1) / 100.0, o));
      CHECK(drawn == doctest::Approx(track.lapLength(o)).epsilon(0.001));
    }
  }
}

TEST_CASE("view geometry: the oval's first curve turns left around its centre; +offset is outer") {
  auto track = sim::namedLayout("oval").value();  // start S L L S S L L
  REQUIRE(track.pieces()[3].turn == 1);
  Pose start = pieceStart(track, 3);
  CHECK(start.heading == doctest::Approx(0));
  Pose mid = pointOnTrack(track, 3, 0.5, 0);
  CHECK(mid.heading == doctest::Approx(45));
  // centre of the arc: one radius to the left (+y) of the piece's start
  const double cx = start.x, cy = start.y + anki::kCurveRadiusMm;
  CHECK(std::hypot(mid.x - cx, mid.y - cy) == doctest::Approx(280));
  Pose outer = pointOnTrack(track, 3, 0.5, 68), inner = pointOnTrack(track, 3, 0.5, -68);
  CHECK(std::hypot(outer.x - cx, outer.y - cy) == doctest::Approx(348));
  CHECK(std::hypot(inner.x - cx, inner.y - cy) == doctest::Approx(212));
  // on a straight heading +x, right (+offset) is −y
  Pose right = pointOnTrack(track, 0, 0.5, 68);
  CHECK(right.y == doctest::Approx(-68));
  CHECK(right.x == doctest::Approx(170));
}

TEST_CASE("view geometry: trackJson has the pieces, the finish line and bounds around the road") {
  auto track = sim::namedLayout("oval").value();
  auto j = trackJson(track, "layout");
  CHECK(j["name"] == "oval");
  CHECK(j["source"] == "layout");
  REQUIRE(j["pieces"].size() == track.size());
  CHECK(j["pieces"][0]["id"] == 34);
  CHECK(j["pieces"][1]["id"] == 33);
  CHECK(j["finish"]["x"] == doctest::Approx(340));  // the end of piece 34
  CHECK(j["lapLength"].get<double>() == doctest::Approx(track.lapLength(0)));
  const auto& b = j["bounds"];
  for (std::size_t i = 0; i < track.size(); ++i)
    for (double f : {0.0, 0.3, 0.7, 1.0})
      for (double o : {-96.0, 96.0}) {
        Pose p = pointOnTrack(track, i, f, o);
        CHECK(p.x >= b["minX"].get<double>() - 0.01);
        CHECK(p.x <= b["maxX"].get<double>() + 0.01);
        CHECK(p.y >= b["minY"].get<double>() - 0.01);
        CHECK(p.y <= b["maxY"].get<double>() + 0.01);
      }
}

TEST_CASE("view geometry: the SVG draws the road, four lanes, the finish line and every piece id") {
  auto track = sim::namedLayout("oval").value();
  std::string svg = trackSvg(track);
  CHECK(svg.starts_with("<svg "));
  CHECK(svg.find("class=\"road\"") != std::string::npos);
  std::size_t lanes = 0;
  for (auto at = svg.find("class=\"lane\""); at != std::string::npos;
       at = svg.find("class=\"lane\"", at + 1))
    ++lanes;
  CHECK(lanes == 4);
  CHECK(svg.find("id=\"finish-line\"") != std::string::npos);
  CHECK(svg.find(">34</text>") != std::string::npos);
  CHECK(svg.find(">33</text>") != std::string::npos);
  CHECK(trackSummary(track).find("9 pieces") != std::string::npos);
}
