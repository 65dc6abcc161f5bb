#include "engine/sim/footprint.hpp"

// GCC 12 warns inside Boost.Geometry's intersection (rescale_policy's `factor`): a known false
// positive of -Wmaybe-uninitialized in Boost 1.74's headers, not about this file's code.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>
#include <cmath>

namespace pitwall::sim {

namespace {

namespace bg = boost::geometry;
using Point = bg::model::d2::point_xy<double>;
using Polygon = bg::model::polygon<Point>;
using MultiPolygon = bg::model::multi_polygon<Polygon>;

// Overlaps smaller than this are the play between pieces and the arcs' chords, not a crossing.
constexpr double kSliverMm2 = 100;

Polygon road(const Piece& p, const Pose& start) {
  // Along both edges; a curve in steps of at most 2° (a chord within 0.8 mm of its arc at the
  // largest radius, 5096 mm: well inside the sliver allowed below).
  const int steps = p.turn ? std::max(1, static_cast<int>(std::ceil(p.angle() / 2))) : 1;
  Polygon poly;
  auto& ring = poly.outer();
  for (int i = 0; i <= steps; ++i) {
    Pose q = poseOnPiece(p, start, static_cast<double>(i) / steps, -kRoadHalfWidthMm);
    ring.emplace_back(q.x, q.y);
  }
  for (int i = steps; i >= 0; --i) {
    Pose q = poseOnPiece(p, start, static_cast<double>(i) / steps, kRoadHalfWidthMm);
    ring.emplace_back(q.x, q.y);
  }
  ring.push_back(ring.front());
  bg::correct(poly);
  return poly;
}

}  // namespace

std::optional<std::pair<std::size_t, std::size_t>> firstOverlap(const std::vector<Piece>& pieces) {
  const std::size_t n = pieces.size();
  std::vector<Polygon> roads;
  std::vector<bg::model::box<Point>> boxes;
  roads.reserve(n);
  Pose at;
  for (const Piece& p : pieces) {
    roads.push_back(road(p, at));
    bg::model::box<Point> box{roads.back().outer().front(), roads.back().outer().front()};
    for (const Point& q : roads.back().outer()) bg::expand(box, q);
    boxes.push_back(box);
    at = poseOnPiece(p, at, 1.0, 0);
  }
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = a + 2; b < n; ++b) {
      if (a == 0 && b == n - 1) continue;  // the loop's ends meet there
      if (!bg::intersects(boxes[a], boxes[b])) continue;
      MultiPolygon common;
      bg::intersection(roads[a], roads[b], common);
      if (bg::area(common) > kSliverMm2) return std::pair{a, b};
    }
  return std::nullopt;
}

}  // namespace pitwall::sim
