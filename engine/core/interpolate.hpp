#pragma once
// Linear interpolation in a table of points sorted by a key (a lap's time at a distance, its
// distance at a time: engine/laps/trace, the simulator's ghost).
#include <algorithm>
#include <limits>

namespace pitwall {

// The value at `x` of `points`, sorted by key(point) (never decreasing): linear between the two
// points around x, the first's or the last's value outside them, NaN when there are none.
template <class Points, class Key, class Value>
double interpolate(const Points& points, double x, Key key, Value value) {
  if (points.empty()) return std::numeric_limits<double>::quiet_NaN();
  auto it = std::lower_bound(points.begin(), points.end(), x,
                             [&](const auto& p, double v) { return key(p) < v; });
  if (it == points.begin()) return value(points.front());
  if (it == points.end()) return value(points.back());
  const auto& a = *(it - 1);
  const auto& b = *it;
  const double ka = key(a), kb = key(b);
  if (kb <= ka) return value(b);
  return value(a) + (value(b) - value(a)) * (x - ka) / (kb - ka);
}

}  // namespace pitwall
