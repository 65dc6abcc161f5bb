#pragma once
// What a simulated car's optical sensor and firmware report, beside what it does: the chance
// that passing a code section yields a position update, the speed it reads, and the collision
// reports it sends with no collision. `Real` is fitted to frames of a physical car
// (../shared/realdata, docs/simulator.md "Sensor model"); `Ideal` reports every code, the exact
// speed and only real contacts; `Transitions` is the worst case a script must survive: the real
// model without a single position update (only the 0x29 at each boundary).
#include <optional>
#include <string_view>

#include "engine/protocol/anki/pieces.hpp"

namespace pitwall::sim {

enum class SensorModel { Real, Ideal, Transitions };

std::string_view sensorModelName(SensorModel model);  // "real", "ideal", "transitions"
std::optional<SensorModel> sensorModelNamed(std::string_view name);  // nullopt: unknown

namespace sensor {

// The chance that a car passing a code section at `speed_mm_s` reads it: on a curve, by the
// lateral acceleration of its lane (radius `lane_radius_mm`); on a straight or a start piece,
// by speed.
double readChance(SensorModel model, anki::PieceType type, double speed_mm_s,
                  double lane_radius_mm);

// The speed a position update reports for a true speed, given two uniform draws in [0, 1): the
// real cars' readings scatter about ±11 % around it (triangular).
double reportedSpeed(SensorModel model, double speed_mm_s, double u1, double u2);

// The chance that crossing a piece boundary at this speed sends a collision report (side 0,
// front/back 1) with no car near.
double phantomCollisionChance(SensorModel model, double speed_mm_s);

// Whether braking to a halt from this speed sends the collision report (side 1, front/back 0)
// every real car in the captures sent after its stop.
bool reportsHalt(SensorModel model, double speed_mm_s);

}  // namespace sensor
}  // namespace pitwall::sim
