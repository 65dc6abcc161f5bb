#include "engine/sim/alphabot_room.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

namespace pitwall::sim::alphabot {

double Rect::distanceTo(double px, double py) const {
  double dx = std::max({x - px, 0.0, px - (x + width)});
  double dy = std::max({y - py, 0.0, py - (y + height)});
  return std::hypot(dx, dy);
}

Room defaultRoom() {
  Room room;
  room.obstacles.push_back({180, 100, 40, 100});
  room.anchors = {{1, 0, 0}, {2, 400, 0}, {3, 0, 300}};
  return room;
}

Result<Room, std::string> parseRoom(std::string_view text, const std::string& source) {
  Room room;
  room.obstacles.clear();
  room.anchors.clear();
  bool sized = false, placed = false;
  std::istringstream in{std::string(text)};
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::string keyword;
    if (!(words >> keyword)) continue;
    std::vector<double> v;
    std::string word;
    auto where = source + ":" + std::to_string(number) + ": ";
    while (words >> word) {
      char* end = nullptr;
      double d = std::strtod(word.c_str(), &end);
      if (end != word.c_str() + word.size() || !std::isfinite(d))
        return Unexpected{where + "'" + word + "' is not a number"};
      v.push_back(d);
    }
    auto arity = [&](std::size_t lo, std::size_t hi,
                     const char* usage) -> std::optional<std::string> {
      if (v.size() < lo || v.size() > hi)
        return where + keyword + " takes " + usage + ", got " + std::to_string(v.size()) +
               " number(s)";
      return std::nullopt;
    };
    if (keyword == "room") {
      if (auto e = arity(2, 2, "WIDTH HEIGHT")) return Unexpected{*e};
      if (sized) return Unexpected{where + "a second room line"};
      if (v[0] < 50 || v[0] > 10000 || v[1] < 50 || v[1] > 10000)
        return Unexpected{where + "room size must be 50..10000 cm each way"};
      room.width = v[0];
      room.height = v[1];
      sized = true;
    } else if (keyword == "robot") {
      if (auto e = arity(2, 3, "X Y [HEADING]")) return Unexpected{*e};
      room.startX = v[0];
      room.startY = v[1];
      room.startHeading = v.size() > 2 ? v[2] : 0;
      placed = true;
    } else if (keyword == "obstacle") {
      if (auto e = arity(4, 4, "X Y WIDTH HEIGHT")) return Unexpected{*e};
      if (v[2] <= 0 || v[3] <= 0)
        return Unexpected{where + "obstacle width and height must be > 0"};
      room.obstacles.push_back({v[0], v[1], v[2], v[3]});
    } else if (keyword == "anchor") {
      if (auto e = arity(3, 3, "ID X Y")) return Unexpected{*e};
      if (v[0] < 0 || v[0] > 255 || v[0] != std::floor(v[0]))
        return Unexpected{where + "anchor id must be a whole number 0..255"};
      room.anchors.push_back({static_cast<int>(v[0]), v[1], v[2]});
    } else {
      return Unexpected{where + "unknown statement '" + keyword +
                        "'; use room, robot, obstacle or anchor"};
    }
  }
  if (placed) {
    if (room.startX <= 0 || room.startX >= room.width || room.startY <= 0 ||
        room.startY >= room.height)
      return Unexpected{source + ": the robot's start (" + std::to_string(room.startX) + ", " +
                        std::to_string(room.startY) + ") is outside the room"};
  } else {
    room.startX = std::min(50.0, room.width / 2);
    room.startY = room.height / 2;
  }
  for (const auto& o : room.obstacles)
    if (o.contains(room.startX, room.startY))
      return Unexpected{source + ": the robot's start is inside an obstacle"};
  return room;
}

Result<Room, std::string> loadRoom(const std::string& path) {
  std::ifstream f(path);
  if (!f) return Unexpected{"cannot read room file '" + path + "'"};
  std::stringstream s;
  s << f.rdbuf();
  return parseRoom(s.str(), path);
}

namespace {

// Slab test: the ray's entry distance into the rectangle, if it enters it ahead of the origin.
std::optional<double> rayRect(double x, double y, double dx, double dy, const Rect& r) {
  double tmin = 0, tmax = std::numeric_limits<double>::infinity();
  auto slab = [&](double o, double d, double lo, double hi) {
    if (std::abs(d) < 1e-12) return o >= lo && o <= hi;
    double t1 = (lo - o) / d, t2 = (hi - o) / d;
    if (t1 > t2) std::swap(t1, t2);
    tmin = std::max(tmin, t1);
    tmax = std::min(tmax, t2);
    return tmin <= tmax;
  };
  if (!slab(x, dx, r.x, r.x + r.width) || !slab(y, dy, r.y, r.y + r.height)) return std::nullopt;
  return tmin;
}

}  // namespace

double castRay(const Room& room, double x, double y, double degrees) {
  double a = degrees * std::numbers::pi / 180;
  double dx = std::cos(a), dy = std::sin(a);
  // Inside the room, the walls are where the ray leaves [0,W]×[0,H].
  double best = std::numeric_limits<double>::infinity();
  if (dx > 1e-12) best = std::min(best, (room.width - x) / dx);
  if (dx < -1e-12) best = std::min(best, -x / dx);
  if (dy > 1e-12) best = std::min(best, (room.height - y) / dy);
  if (dy < -1e-12) best = std::min(best, -y / dy);
  for (const auto& o : room.obstacles)
    if (auto t = rayRect(x, y, dx, dy, o)) best = std::min(best, *t);
  return std::max(0.0, best);
}

bool collides(const Room& room, double x, double y, double radius) {
  if (x - radius < 0 || y - radius < 0 || x + radius > room.width || y + radius > room.height)
    return true;
  for (const auto& o : room.obstacles)
    if (o.distanceTo(x, y) < radius) return true;
  return false;
}

}  // namespace pitwall::sim::alphabot
