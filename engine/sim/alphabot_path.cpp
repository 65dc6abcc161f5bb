#include "engine/sim/alphabot_path.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

namespace pitwall::sim::alphabot {
namespace {

bool free(const PathQuery& q, double x, double y) {
  double c = q.clearance;
  if (x < c || y < c || x > q.width - c || y > q.height - c) return false;
  for (const auto& o : q.obstacles)
    if (o.distanceTo(x, y) < c) return false;
  return true;
}

// The straight leg a→b keeps its clearance all along (sampled every half cell).
bool clearLine(const PathQuery& q, Point a, Point b) {
  double length = std::hypot(b.x - a.x, b.y - a.y);
  int steps = std::max(1, static_cast<int>(std::ceil(length / (q.cell / 2))));
  for (int i = 1; i <= steps; ++i) {
    double t = static_cast<double>(i) / steps;
    if (!free(q, a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t)) return false;
  }
  return true;
}

}  // namespace

std::vector<Point> findPath(const PathQuery& q, Point from, Point to) {
  if (!free(q, to.x, to.y)) return {};
  if (clearLine(q, from, to)) return {to};
  int nx = static_cast<int>(q.width / q.cell) + 1, ny = static_cast<int>(q.height / q.cell) + 1;
  auto centre = [&](int i) { return Point{(i % nx) * q.cell, (i / nx) * q.cell}; };
  auto cellOf = [&](Point p) {
    int cx = std::clamp(static_cast<int>(std::lround(p.x / q.cell)), 0, nx - 1);
    int cy = std::clamp(static_cast<int>(std::lround(p.y / q.cell)), 0, ny - 1);
    return cy * nx + cx;
  };
  std::vector<char> open(static_cast<std::size_t>(nx * ny));
  for (int i = 0; i < nx * ny; ++i) {
    Point c = centre(i);
    open[static_cast<std::size_t>(i)] = free(q, c.x, c.y);
  }
  int start = cellOf(from), goal = cellOf(to);
  // The robot may stand closer to something than the clearance (it was driven there): its own
  // cell is always usable, and so is the goal's (the target itself is free).
  open[static_cast<std::size_t>(start)] = 1;
  open[static_cast<std::size_t>(goal)] = 1;

  std::vector<double> g(static_cast<std::size_t>(nx * ny), std::numeric_limits<double>::infinity());
  std::vector<int> parent(static_cast<std::size_t>(nx * ny), -1);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> frontier;
  auto h = [&](int i) {
    Point a = centre(i), b = centre(goal);
    return std::hypot(a.x - b.x, a.y - b.y);
  };
  g[static_cast<std::size_t>(start)] = 0;
  frontier.push({h(start), start});
  while (!frontier.empty()) {
    auto [f, cur] = frontier.top();
    frontier.pop();
    if (cur == goal) break;
    if (f > g[static_cast<std::size_t>(cur)] + h(cur) + 1e-9) continue;
    int cx = cur % nx, cy = cur / nx;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (!dx && !dy) continue;
        int x = cx + dx, y = cy + dy;
        if (x < 0 || y < 0 || x >= nx || y >= ny) continue;
        int n = y * nx + x;
        if (!open[static_cast<std::size_t>(n)]) continue;
        // No cutting corners: a diagonal step needs both straight neighbours open.
        if (dx && dy &&
            (!open[static_cast<std::size_t>(cy * nx + x)] ||
             !open[static_cast<std::size_t>(y * nx + cx)]))
          continue;
        double cost =
            g[static_cast<std::size_t>(cur)] + q.cell * ((dx && dy) ? std::sqrt(2.0) : 1.0);
        if (cost < g[static_cast<std::size_t>(n)]) {
          g[static_cast<std::size_t>(n)] = cost;
          parent[static_cast<std::size_t>(n)] = cur;
          frontier.push({cost + h(n), n});
        }
      }
  }
  if (start != goal && parent[static_cast<std::size_t>(goal)] < 0) return {};

  std::vector<Point> cells;
  for (int i = goal; i != start; i = parent[static_cast<std::size_t>(i)])
    cells.push_back(centre(i));
  std::reverse(cells.begin(), cells.end());
  cells.back() = to;
  // Line-of-sight shortening: from where the robot is, go to the farthest cell still in sight.
  std::vector<Point> path;
  Point at = from;
  std::size_t i = 0;
  while (i < cells.size()) {
    std::size_t far = i;
    for (std::size_t j = cells.size(); j-- > i;)
      if (clearLine(q, at, cells[j])) {
        far = j;
        break;
      }
    path.push_back(cells[far]);
    at = cells[far];
    i = far + 1;
  }
  return path;
}

}  // namespace pitwall::sim::alphabot
