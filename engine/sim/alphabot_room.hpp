#pragma once
// The simulated Alphabot's room (docs/robots.md, "Room files"): a rectangle of walls in
// cm (x to the right, y up, the origin in a corner), the physical obstacles the distance sensor
// sees and the robot bumps into, the positioning anchors, and where the robot starts.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/result.hpp"

namespace pitwall::sim::alphabot {

struct Rect {
  double x = 0, y = 0, width = 0, height = 0;  // x, y: the corner nearest the origin
  bool contains(double px, double py) const {
    return px >= x && px <= x + width && py >= y && py <= y + height;
  }
  // Distance from a point to the rectangle (0 inside).
  double distanceTo(double px, double py) const;
};

struct Anchor {
  int id = 0;
  double x = 0, y = 0;
};

struct Room {
  double width = 400, height = 300;
  std::vector<Rect> obstacles;
  std::vector<Anchor> anchors;
  double startX = 50, startY = 150,
         startHeading = 0;  // heading: degrees, 0 = +x, counter-clockwise
};

// 400 × 300 cm, one box of 40 × 100 cm in the middle (x 180..220, y 100..200), anchors in three
// corners, the robot at (50, 150) facing +x (towards the box).
Room defaultRoom();

// The text format: one statement per line, `#` starts a comment, numbers in cm / degrees:
//   room WIDTH HEIGHT            (once, first; 50..10000)
//   robot X Y [HEADING]          (start pose; inside the room)
//   obstacle X Y WIDTH HEIGHT    (any number)
//   anchor ID X Y                (id 0..255)
// Errors name the source, the line and what is wrong.
Result<Room, std::string> parseRoom(std::string_view text, const std::string& source);
Result<Room, std::string> loadRoom(const std::string& path);

// Distance from (x, y) along `degrees` (world frame) to the first wall or obstacle, cm.
double castRay(const Room& room, double x, double y, double degrees);
// A disc of `radius` at (x, y) overlaps a wall or an obstacle.
bool collides(const Room& room, double x, double y, double radius);

}  // namespace pitwall::sim::alphabot
