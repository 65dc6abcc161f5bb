#include "engine/sim/sensor.hpp"

#include <algorithm>
#include <cmath>

namespace pitwall::sim {

namespace {

// The fit (docs/simulator.md "Sensor model" has the data behind each number). A logistic
// 1 / (1 + e^((x − x50) / width)) falls from 1 to 0 around x50.
double logistic(double x, double x50, double width) {
  return 1.0 / (1.0 + std::exp((x - x50) / width));
}

// Straights: every code read at 250 mm/s, 2.25–2.75 of 3 per straight at 750 (p ≈ 0.87).
constexpr double kStraightSpeed50 = 1035;  // mm/s
constexpr double kStraightWidth = 150;
// Curves, by the lane's lateral acceleration v²/r: all codes at 250 mm/s on the middle lanes,
// 0–0.5 per curve at 750 (p ≈ 0.17 on the outer lane, 0.08 on the next, none inside).
constexpr double kCurveAccel50 = 1145;  // mm/s²
constexpr double kCurveAccelWidth = 296;
// The innermost lane of a stock curve (radius 212 mm) read half its codes even at 250 mm/s.
constexpr double kTightRadiusMm = 240;
constexpr double kTightFactor = 0.5;
// The reported speed: 191–279 for 250, 669–836 for 750 (sd ≈ 4.5 %).
constexpr double kSpeedScatter = 0.11;
// Collision reports at a boundary with no car near: 18 in 47 boundaries at 750, none in 44 at
// 250; above 750 no data, so no more often than the most seen (7 of 12 on an inner lane).
constexpr double kPhantomSpeed50 = 810;  // mm/s
constexpr double kPhantomWidth = 122;
constexpr double kPhantomMax = 0.6;
// A halt from speed: 8 runs of 8 sent one.
constexpr double kHaltFromMmS = 200;

}  // namespace

std::string_view sensorModelName(SensorModel model) {
  switch (model) {
    case SensorModel::Ideal: return "ideal";
    case SensorModel::Transitions: return "transitions";
    case SensorModel::Real: break;
  }
  return "real";
}

std::optional<SensorModel> sensorModelNamed(std::string_view name) {
  if (name == "real") return SensorModel::Real;
  if (name == "ideal") return SensorModel::Ideal;
  if (name == "transitions") return SensorModel::Transitions;
  return std::nullopt;
}

namespace sensor {

double readChance(SensorModel model, anki::PieceType type, double speed_mm_s,
                  double lane_radius_mm) {
  if (model == SensorModel::Ideal) return 1;
  if (model == SensorModel::Transitions) return 0;
  if (type != anki::PieceType::Curve) return logistic(speed_mm_s, kStraightSpeed50, kStraightWidth);
  if (lane_radius_mm <= 0) return 0;
  double p = logistic(speed_mm_s * speed_mm_s / lane_radius_mm, kCurveAccel50, kCurveAccelWidth);
  return lane_radius_mm < kTightRadiusMm ? p * kTightFactor : p;
}

double reportedSpeed(SensorModel model, double speed_mm_s, double u1, double u2) {
  if (model == SensorModel::Ideal) return speed_mm_s;
  return speed_mm_s * (1 + kSpeedScatter * (u1 + u2 - 1));
}

double phantomCollisionChance(SensorModel model, double speed_mm_s) {
  if (model == SensorModel::Ideal || speed_mm_s <= 0) return 0;
  return std::min(kPhantomMax, 1 - logistic(speed_mm_s, kPhantomSpeed50, kPhantomWidth));
}

bool reportsHalt(SensorModel model, double speed_mm_s) {
  return model != SensorModel::Ideal && speed_mm_s >= kHaltFromMmS;
}

}  // namespace sensor
}  // namespace pitwall::sim
