#pragma once
// Where the controller believes a car is, from the frames it sends (docs/view.md "Cars"): the
// piece of the track (matched by id along the driving order), the fraction of it, and its laps.
// The view's feed and `pitwall replay` follow every car through one of these. A lap ends on the
// transition from the start piece (34) to the piece after the finish line (33) driving forward
// (as pitwall.laps counts it); the first crossing starts lap 1. A real car at speed sends no
// position update on most curves, so the transitions carry the car on along the map, and a lap
// whose start piece sent none still ends at the line (docs/view.md "Cars").
#include <optional>
#include <vector>

#include "engine/protocol/anki/messages.hpp"
#include "engine/sim/track.hpp"
#include "engine/vehicles/anki_car.hpp"

namespace pitwall::laps {

class CarTracker {
 public:
  // Follows a car on `track` (none: laps are still counted, no position is known).
  void setTrack(const sim::Track* track);
  // A frame from the car (its state already updated), at engine time `now`.
  void update(const anki::Message& message, const CarState& state, double now);
  void delocalized() { index_.reset(); }

  std::optional<std::size_t> pieceIndex() const { return index_; }
  double fraction() const { return fraction_; }
  double positionTime() const { return positionTime_; }  // when index/fraction were last set
  // Where along its piece the car is at `now`: the last known fraction moved on by its speed
  // along its lane since then, but never past the piece's end — the transition says when it
  // left (a real car at speed reports no position on most curves: docs/view.md "Cars").
  double fractionAt(double now, double speed_mm_s, double offset_mm, bool reverse) const;

  int laps() const { return static_cast<int>(lapTimes_.size()); }
  const std::vector<double>& lapTimes() const { return lapTimes_; }
  std::optional<double> bestLap() const { return best_; }
  // When the car last crossed the line (none: not yet): the start of the lap under way.
  std::optional<double> lastCrossing() const { return lastCrossing_; }

 private:
  void crossFinish(double now);
  void transition(bool reverse, double now);
  void placeEarlierTransitions();
  int currentPieceId() const;
  std::optional<std::size_t> locate(int pieceId, bool reverse) const;
  double codeFraction(const sim::Piece& piece, long key, int location);

  const sim::Track* track_ = nullptr;
  std::optional<std::size_t> index_;
  long fractionsKey_ = -1;  // whose code fractions fractions_ holds (codeFraction)
  std::vector<double> fractions_;
  double fraction_ = 0;
  double positionTime_ = -1;
  int lastPieceId_ = -1;
  bool crossedSinceStartPiece_ = false;
  // Times of the transitions a car made before it ever said where it was (a real car pulling
  // away from the grid fast may report nothing before the line): placed once it reports.
  std::vector<double> unplaced_;
  std::optional<double> lastCrossing_;
  // Without a map: transitions since the line (none: not known), and the pieces of a lap once
  // two crossings in a row showed it
  std::optional<int> sinceLine_;
  std::optional<int> lapPieces_;
  std::vector<double> lapTimes_;
  std::optional<double> best_;
};

}  // namespace pitwall::laps
