#pragma once
// The robot side of the Alphabot protocol, simulated (docs/robots.md): a disc of 10 cm
// radius in a Room, driven by speed/steer, with a distance sensor on a servo, a compass,
// positioning, an obstacle map and path finding. Pure model: requests in, responses out through
// `emit`, time advanced by step(); the TCP side is RobotServer (alphabot_server.hpp).
//
// Units and frames: cm, degrees; x right, y up; heading 0 = +x, counter-clockwise positive.
// Speed s (−128..127) drives at s × 0.5 cm/s; steer t turns at −t °/s (negative steer: left,
// i.e. counter-clockwise). The sensor's degree is relative to the heading (counter-clockwise).
#include <functional>
#include <optional>
#include <vector>

#include "engine/protocol/alphabot/messages.hpp"
#include "engine/sim/alphabot_path.hpp"
#include "engine/sim/alphabot_room.hpp"

namespace pitwall::sim::alphabot {

struct RobotConfig {
  double radius = 10;               // cm
  double cmPerSpeedUnit = 0.5;      // cm/s per unit of drive speed
  double degPerSteerUnit = 1.0;     // °/s per unit of steer
  double navigationSpeed = 30;      // cm/s while following a path
  double navigationTurnRate = 180;  // °/s while turning towards the next waypoint
  double avoidanceMargin = 5;       // cm left between the robot's edge and an obstacle
  double reportPeriod = 0.25;       // s between periodic reports (positions, compass, distance)
};

struct MapObstacle {
  std::uint8_t id = 0;
  Rect rect;
};

class Robot {
 public:
  explicit Robot(Room room, RobotConfig config = {});

  void receive(const pitwall::alphabot::Request& request);
  void step(double dt);  // seconds
  std::function<void(const pitwall::alphabot::Response&)> emit;

  // Ground truth, for tests and logs.
  double x() const { return x_; }
  double y() const { return y_; }
  double heading() const { return heading_; }  // 0..360
  bool moving() const { return speed_ != 0 || navigating_; }
  bool navigating() const { return navigating_; }
  bool bumped() const { return bumped_; }    // the last stop was a collision
  bool avoided() const { return avoided_; }  // the last stop was collision avoidance
  const Room& room() const { return room_; }
  const std::vector<MapObstacle>& map() const { return map_; }
  const pitwall::alphabot::Toggles& toggles() const { return toggles_; }
  void place(double x, double y, double heading);

 private:
  void send(const pitwall::alphabot::Response& r) {
    if (emit) emit(r);
  }
  void reportPosition();
  void reportCompass();
  std::uint16_t measure(double relativeDegrees) const;
  void navigate(double x, double y);
  void driveFree(double dt);
  void followPath(double dt);
  // Moves by (dx, dy) unless the disc would overlap something: then stops and says so.
  bool moveTo(double nx, double ny);
  double clearanceAhead(double direction) const;
  bool on(const char* toggle) const;

  Room room_;
  RobotConfig config_;
  double x_, y_, heading_;
  int speed_ = 0, steer_ = 0;
  bool bumped_ = false, avoided_ = false;
  bool navigating_ = false;
  std::vector<Point> path_;
  std::size_t leg_ = 0;
  std::vector<MapObstacle> map_;
  std::vector<Anchor> anchors_;
  std::uint8_t nextId_ = 1;
  pitwall::alphabot::Toggles toggles_;
  double sinceReport_ = 0;
};

}  // namespace pitwall::sim::alphabot
