#pragma once
// Path finding for the simulated Alphabot: A* on a grid over the room, keeping `clearance` cm
// (the robot's radius and a margin) from the walls and from the obstacles of the robot's map,
// then shortened by line of sight so the path is a few straight legs.
#include <vector>

#include "engine/sim/alphabot_room.hpp"

namespace pitwall::sim::alphabot {

struct Point {
  double x = 0, y = 0;
};

struct PathQuery {
  double width = 400, height = 300;  // the room, cm
  std::vector<Rect> obstacles;       // what the robot knows of (its map)
  double clearance = 13;             // cm kept from every wall and obstacle
  double cell = 5;                   // grid resolution, cm
};

// The waypoints from `from` (excluded) to `to` (the last one, exactly), or an empty list when
// the target is outside the room, too close to an obstacle or a wall, or cut off.
std::vector<Point> findPath(const PathQuery& query, Point from, Point to);

}  // namespace pitwall::sim::alphabot
