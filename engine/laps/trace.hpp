#pragma once
// A lap as a trace (docs/racing.md "Comparing laps"): where a car was along the track, and when,
// from the frames it sent — each position update placed on the map at its code, each transition
// at its piece's boundary, the lap closed where the tracker counted it. Distances are along the
// track's centre line from the finish line, so two laps on different lanes line up.
//
// A real car at speed sends no position update on most curves (../shared/realdata): such a
// piece has only its boundaries, and the trace says so (pieceReported), so a comparison can
// tell what it knows by distance from what it knows per piece.
#include <cstddef>
#include <optional>
#include <vector>

#include "engine/laps/tracker.hpp"
#include "engine/protocol/anki/messages.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::laps {

// The track in lap order: piece k of a lap is the track's piece (finishIndex + k) % n.
struct LapMap {
  explicit LapMap(const sim::Track& track);
  std::size_t lapIndex(std::size_t trackIndex) const;  // k of a track's piece
  std::size_t trackIndex(std::size_t k) const;
  std::vector<double> start;       // by k: mm from the line to the piece's start (centre line)
  std::vector<double> length;      // by k: the piece's centre-line length, mm
  std::vector<sim::Piece> pieces;  // by k: its shape (a lane's length)
  double lap = 0;                  // mm
  std::size_t finish = 0, n = 0;
};

struct TracePoint {
  double t = 0;         // seconds since the lap began (the car crossed the line)
  double distance = 0;  // mm along the centre line from the line
  double speed = 0;     // mm/s as the car reported it; NaN at a transition (it tells none)
  double offset = 0;    // mm right of the road's centre as reported; NaN at a transition
};

struct LapTrace {
  int lap = 0;        // its number, from 1, as the tracker counts laps
  double start = 0;   // engine seconds at the line
  double time = 0;    // the lap's time, s
  double length = 0;  // centre-line length of a lap, mm
  // driven forward all the way (no U-turn, never lost off the map), every piece seen (its
  // transition or a position update from it)
  bool clean = true;
  std::vector<TracePoint> points;    // distance never decreasing, from (0, 0) to (time, length)
  std::vector<double> pieceEntered;  // by k: s since the line the car entered piece k; NaN: unseen
  std::vector<bool> pieceReported;   // by k: a position update came from the piece

  bool everyPieceReported() const;
  // The time at a distance and the distance at a time: linear between the points around it.
  double timeAt(double distance) const;
  double distanceAt(double t) const;
  // When the car entered piece k: the transition's time, else the trace's at its start.
  double enteredAt(std::size_t k, const LapMap& map) const;
  // The car's offset on piece k as it last reported it there or before (0: never).
  double offsetOn(std::size_t k, const LapMap& map) const;
};

// Builds the traces of one car's laps from the frames it sends, beside its CarTracker.
class TraceBuilder {
 public:
  void setTrack(const sim::Track* track);
  // A frame from the car, after `tracker` took it: a finished lap when this frame ended one.
  std::optional<LapTrace> update(const CarTracker& tracker, const anki::Message& message,
                                 bool reverse, double now);
  // The lap under way (nullptr before the first crossing, or with no map): for a live delta.
  const LapTrace* current() const { return current_ ? &*current_ : nullptr; }
  // Where the car is along the lap under way now (mm from the line), moved on by its speed
  // since the last frame as the tracker does; none before the first crossing.
  std::optional<double> distanceNow(const CarTracker& tracker, double now, double speed,
                                    double offset, bool reverse) const;
  void reset();

 private:
  void add(TracePoint point);

  std::optional<LapMap> map_;
  const sim::Track* track_ = nullptr;
  std::optional<double> crossing_;  // the tracker's last crossing, as last seen
  std::optional<LapTrace> current_;
};

}  // namespace pitwall::laps
