#include "engine/laps/trace.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>

#include "engine/core/interpolate.hpp"

namespace pitwall::laps {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

LapMap::LapMap(const sim::Track& track) : finish(track.finishIndex()), n(track.size()) {
  start.resize(n);
  length.resize(n);
  double at = 0;
  for (std::size_t k = 0; k < n; ++k) {
    start[k] = at;
    pieces.push_back(track.piece(trackIndex(k)));
    length[k] = pieces.back().length(0);
    at += length[k];
  }
  lap = at;
}

std::size_t LapMap::lapIndex(std::size_t trackIndex) const {
  return (trackIndex + n - finish % n) % n;
}

std::size_t LapMap::trackIndex(std::size_t k) const {
  return (finish + k) % n;
}

bool LapTrace::everyPieceReported() const {
  return std::all_of(pieceReported.begin(), pieceReported.end(), [](bool r) { return r; });
}

double LapTrace::timeAt(double distance) const {
  return interpolate(
      points, distance, [](const TracePoint& p) { return p.distance; },
      [](const TracePoint& p) { return p.t; });
}

double LapTrace::distanceAt(double t) const {
  return interpolate(
      points, t, [](const TracePoint& p) { return p.t; },
      [](const TracePoint& p) { return p.distance; });
}

double LapTrace::enteredAt(std::size_t k, const LapMap& map) const {
  if (k == 0) return 0;
  if (k >= map.n) return time;
  if (k < pieceEntered.size() && std::isfinite(pieceEntered[k])) return pieceEntered[k];
  return timeAt(map.start[k]);
}

double LapTrace::offsetOn(std::size_t k, const LapMap& map) const {
  const double end = k + 1 < map.n ? map.start[k + 1] : map.lap;
  double offset = 0;
  for (const TracePoint& p : points) {
    if (p.distance >= end) break;
    if (std::isfinite(p.offset)) offset = p.offset;
  }
  return offset;
}

void TraceBuilder::setTrack(const sim::Track* track) {
  track_ = track && track->size() ? track : nullptr;
  if (track_)
    map_.emplace(*track_);
  else
    map_.reset();
  reset();
}

void TraceBuilder::reset() {
  crossing_.reset();
  current_.reset();
}

void TraceBuilder::add(TracePoint point) {
  auto& points = current_->points;
  if (!points.empty()) {
    const TracePoint& last = points.back();
    if (point.distance < last.distance || point.t < last.t) return;  // a late or stray frame
  }
  points.push_back(point);
}

std::optional<LapTrace> TraceBuilder::update(const CarTracker& tracker,
                                             const anki::Message& message, bool reverse,
                                             double now) {
  if (!map_) return std::nullopt;
  std::optional<LapTrace> finished;
  const auto crossing = tracker.lastCrossing();
  if (crossing && crossing != crossing_) {
    if (current_ && crossing_ && tracker.laps() >= 1 &&
        std::abs(tracker.lapTimes().back() - (*crossing - *crossing_)) < 1e-9) {
      LapTrace& lap = *current_;
      lap.time = *crossing - lap.start;
      add({lap.time, lap.length, kNaN, kNaN});
      // whole: every piece was seen, by its transition or a position update (a lap the tracker
      // jumped across, after a misread, is no lap to race or compare)
      for (std::size_t k = 0; k < lap.pieceEntered.size(); ++k)
        if (!std::isfinite(lap.pieceEntered[k]) && !lap.pieceReported[k]) lap.clean = false;
      finished = std::move(lap);
    }
    crossing_ = crossing;
    LapTrace next;
    next.lap = tracker.laps() + 1;
    next.start = *crossing;
    next.length = map_->lap;
    next.pieceEntered.assign(map_->n, kNaN);
    next.pieceReported.assign(map_->n, false);
    next.pieceEntered[0] = 0;
    next.points.push_back({0, 0, kNaN, kNaN});
    current_ = std::move(next);
  }
  if (!current_) return finished;
  LapTrace& lap = *current_;
  if (reverse) lap.clean = false;
  const auto index = tracker.pieceIndex();
  if (!index) {
    if (std::holds_alternative<anki::Delocalized>(message)) lap.clean = false;
    return finished;
  }
  const std::size_t k = map_->lapIndex(*index);
  const double t = now - lap.start;
  if (const auto* p = std::get_if<anki::PositionUpdate>(&message)) {
    if (reverse) return finished;
    lap.pieceReported[k] = true;
    add({t, map_->start[k] + tracker.fraction() * map_->length[k],
         static_cast<double>(p->speed_mm_s), static_cast<double>(p->offset_mm)});
  } else if (std::holds_alternative<anki::TransitionUpdate>(message) && !reverse && k != 0) {
    if (!std::isfinite(lap.pieceEntered[k])) lap.pieceEntered[k] = t;
    add({t, map_->start[k], kNaN, kNaN});
  }
  return finished;
}

std::optional<double> TraceBuilder::distanceNow(const CarTracker& tracker, double now, double speed,
                                                double offset, bool reverse) const {
  if (!current_ || !map_ || !tracker.pieceIndex()) return std::nullopt;
  const std::size_t k = map_->lapIndex(*tracker.pieceIndex());
  const double d =
      map_->start[k] + tracker.fractionAt(now, speed, offset, reverse) * map_->length[k];
  return std::clamp(d, 0.0, map_->lap);
}

}  // namespace pitwall::laps
