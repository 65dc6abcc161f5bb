#include "engine/sim/alphabot_robot.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "engine/core/overload.hpp"
#include "engine/protocol/alphabot/toggles.hpp"

namespace pitwall::sim::alphabot {

namespace ab = pitwall::alphabot;

namespace {

double wrap360(double d) {
  d = std::fmod(d, 360.0);
  return d < 0 ? d + 360 : d;
}
double wrap180(double d) {
  d = wrap360(d);
  return d > 180 ? d - 360 : d;
}
std::int16_t cm(double v) {
  return static_cast<std::int16_t>(std::clamp(std::lround(v), -32768L, 32767L));
}
constexpr double kRad = std::numbers::pi / 180;

}  // namespace

Robot::Robot(Room room, RobotConfig config)
    : room_(std::move(room)),
      config_(config),
      x_(room_.startX),
      y_(room_.startY),
      heading_(wrap360(room_.startHeading)),
      anchors_(room_.anchors) {}

void Robot::place(double x, double y, double heading) {
  x_ = x;
  y_ = y;
  heading_ = wrap360(heading);
}

bool Robot::on(const char* toggle) const {
  const ab::ToggleBit* bit = ab::findToggle(toggle);
  return bit && ab::isSet(toggles_, *bit);
}

void Robot::reportPosition() {
  send(ab::Position{cm(x_), cm(y_)});
}

void Robot::reportCompass() {
  send(ab::Compass{static_cast<std::int16_t>(std::lround(heading_) % 360)});
}

std::uint16_t Robot::measure(double relativeDegrees) const {
  double d = castRay(room_, x_, y_, heading_ + relativeDegrees);
  return static_cast<std::uint16_t>(std::clamp(std::lround(d), 0L, 65535L));
}

void Robot::receive(const ab::Request& request) {
  std::visit(Overload{
                 [&](const ab::Drive& d) {
                   navigating_ = false;  // a drive command takes over from navigation
                   speed_ = d.speed;
                   steer_ = d.steer;
                   if (speed_ != 0) bumped_ = avoided_ = false;
                 },
                 [&](const ab::MeasureDistance& m) {
                   send(ab::Distance{m.degree, measure(m.degree)});
                 },
                 [&](const ab::CalibrateSteering&) {
                   // The robot calibrates standing still; the WLAN protocol has no answer for it.
                   speed_ = steer_ = 0;
                   navigating_ = false;
                 },
                 [&](const ab::CalibrateCompass&) { reportCompass(); },
                 [&](const ab::SetToggles& t) {
                   bool wasPositioning = on("positioning");
                   toggles_ = t.toggles;
                   if (!wasPositioning && on("positioning")) reportPosition();
                 },
                 [&](const ab::Ping& p) { send(ab::PingReply{p.time}); },
                 [&](const ab::SetAnchor& a) {
                   auto it = std::find_if(anchors_.begin(), anchors_.end(),
                                          [&](const Anchor& k) { return k.id == a.id; });
                   if (it == anchors_.end())
                     anchors_.push_back({a.id, static_cast<double>(a.x), static_cast<double>(a.y)});
                   else
                     *it = {a.id, static_cast<double>(a.x), static_cast<double>(a.y)};
                   if (on("positioning")) reportPosition();
                 },
                 [&](const ab::NavigateTo& n) { navigate(n.x, n.y); },
                 [&](const ab::AddObstacle& o) {
                   // Ids 1..255, the next free one after the last given.
                   for (int tries = 0; tries < 255; ++tries) {
                     std::uint8_t id = nextId_;
                     nextId_ = static_cast<std::uint8_t>(nextId_ == 255 ? 1 : nextId_ + 1);
                     bool used = std::any_of(map_.begin(), map_.end(),
                                             [&](const MapObstacle& m) { return m.id == id; });
                     if (used) continue;
                     map_.push_back(
                         {id, Rect{static_cast<double>(o.x), static_cast<double>(o.y),
                                   static_cast<double>(o.width), static_cast<double>(o.height)}});
                     send(ab::ObstacleRegistered{id, o.x, o.y, o.width, o.height});
                     return;
                   }
                   // A full map (255 obstacles) registers nothing: no answer, as a robot with no
                   // room.
                 },
                 [&](const ab::RemoveObstacleById& r) {
                   std::erase_if(map_, [&](const MapObstacle& m) { return m.id == r.id; });
                 },
                 [&](const ab::RemoveObstacleAt& r) {
                   std::erase_if(map_,
                                 [&](const MapObstacle& m) { return m.rect.contains(r.x, r.y); });
                 },
                 [&](const ab::ClearObstacles&) { map_.clear(); },
             },
             request);
}

void Robot::navigate(double tx, double ty) {
  PathQuery q;
  q.width = room_.width;
  q.height = room_.height;
  q.clearance = config_.radius + 5;  // a margin for steering and sensing errors
  for (const auto& m : map_) q.obstacles.push_back(m.rect);
  path_ = findPath(q, {x_, y_}, {tx, ty});
  ab::Path reply;
  for (const auto& p : path_) {
    if (reply.waypoints.size() == 255) break;
    reply.waypoints.push_back({cm(p.x), cm(p.y)});
  }
  send(reply);
  leg_ = 0;
  speed_ = steer_ = 0;
  navigating_ = !path_.empty();
  bumped_ = avoided_ = false;
}

double Robot::clearanceAhead(double direction) const {
  // Three rays: the centre line and both sides of the body.
  double best = castRay(room_, x_, y_, direction);
  double nx = -std::sin(direction * kRad) * config_.radius;
  double ny = std::cos(direction * kRad) * config_.radius;
  best = std::min(best, castRay(room_, x_ + nx * 0.9, y_ + ny * 0.9, direction));
  best = std::min(best, castRay(room_, x_ - nx * 0.9, y_ - ny * 0.9, direction));
  return best - config_.radius;
}

bool Robot::moveTo(double nx, double ny) {
  if (collides(room_, nx, ny, config_.radius)) {
    speed_ = steer_ = 0;
    navigating_ = false;
    bumped_ = true;
    reportPosition();
    return false;
  }
  x_ = nx;
  y_ = ny;
  return true;
}

void Robot::driveFree(double dt) {
  heading_ = wrap360(heading_ - steer_ * config_.degPerSteerUnit * dt);
  if (speed_ == 0) return;
  double v = speed_ * config_.cmPerSpeedUnit;
  double direction = v >= 0 ? heading_ : heading_ + 180;
  if (on("collisionAvoidance") &&
      clearanceAhead(direction) - std::abs(v) * dt < config_.avoidanceMargin) {
    speed_ = steer_ = 0;
    avoided_ = true;
    reportPosition();
    return;
  }
  moveTo(x_ + v * dt * std::cos(heading_ * kRad), y_ + v * dt * std::sin(heading_ * kRad));
}

void Robot::followPath(double dt) {
  Point target = path_[leg_];
  double dx = target.x - x_, dy = target.y - y_;
  double dist = std::hypot(dx, dy);
  if (dist < 0.5) {
    if (++leg_ == path_.size()) {
      navigating_ = false;
      reportPosition();  // arrived
    }
    return;
  }
  double error = wrap180(std::atan2(dy, dx) / kRad - heading_);
  double turn =
      std::clamp(error, -config_.navigationTurnRate * dt, config_.navigationTurnRate * dt);
  heading_ = wrap360(heading_ + turn);
  if (std::abs(error - turn) > 5) return;  // turn on the spot first
  double stepLength = std::min(dist, config_.navigationSpeed * dt);
  if (on("collisionAvoidance") && clearanceAhead(heading_) - stepLength < config_.avoidanceMargin) {
    navigating_ = false;
    avoided_ = true;
    reportPosition();
    return;
  }
  moveTo(x_ + dx / dist * stepLength, y_ + dy / dist * stepLength);
}

void Robot::step(double dt) {
  if (navigating_)
    followPath(dt);
  else
    driveFree(dt);
  sinceReport_ += dt;
  if (sinceReport_ + 1e-9 < config_.reportPeriod) return;
  sinceReport_ = 0;
  if (on("positioning") || on("logPosition") || navigating_) reportPosition();
  if (on("logCompass")) reportCompass();
  if (on("logObstacleDistance")) send(ab::Distance{0, measure(0)});
}

}  // namespace pitwall::sim::alphabot
