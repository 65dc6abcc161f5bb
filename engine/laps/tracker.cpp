#include "engine/laps/tracker.hpp"

#include <algorithm>

#include "engine/sim/code_layout.hpp"

namespace pitwall::laps {

// Where along a piece a location code lies (docs/tracks.md "The code"): the centre of its
// section, as a fraction of the piece in its own forward direction; location ids name the same
// spot whichever way the car drives. Unknown ids: the middle. The fractions of the piece the car
// is on are kept (`key`: the track's piece index, or the stock piece's id and direction), so a
// position update looks one up instead of walking the piece's code rows.
double CarTracker::codeFraction(const sim::Piece& piece, long key, int location) {
  if (key != fractionsKey_) {
    fractions_ = sim::codeFractions(piece);
    fractionsKey_ = key;
  }
  return location >= 0 && static_cast<std::size_t>(location) < fractions_.size()
             ? fractions_[static_cast<std::size_t>(location)]
             : 0.5;
}

void CarTracker::setTrack(const sim::Track* track) {
  track_ = track && track->size() ? track : nullptr;
  index_.reset();
  fractionsKey_ = -1;
}

std::optional<std::size_t> CarTracker::locate(int pieceId, bool reverse) const {
  if (!track_) return std::nullopt;
  const auto& pieces = track_->pieces();
  const std::size_t n = pieces.size();
  if (index_ && pieces[*index_].id == pieceId) return index_;
  if (index_) {  // the next piece with that id along the driving direction
    for (std::size_t step = 1; step <= n; ++step) {
      std::size_t i = reverse ? (*index_ + n * step - step) % n : (*index_ + step) % n;
      if (pieces[i].id == pieceId) return i;
    }
    return std::nullopt;
  }
  for (std::size_t i = 0; i < n; ++i)
    if (pieces[i].id == pieceId) return i;
  return std::nullopt;
}

void CarTracker::crossFinish(double now) {
  if (lastCrossing_) {
    const double lap = now - *lastCrossing_;
    lapTimes_.push_back(lap);
    if (!best_ || lap < *best_) best_ = lap;
  }
  lastCrossing_ = now;
  crossedSinceStartPiece_ = true;
}

// The id of the piece the car is on: the map's, once it is localized on a known track (the
// transitions carry it on from piece to piece when position updates are missing, as on a real
// car's curves at speed), else the one it last reported.
int CarTracker::currentPieceId() const {
  if (track_ && index_) return track_->pieces()[*index_].id;
  return lastPieceId_;
}

void CarTracker::update(const anki::Message& message, const CarState& state, double now) {
  if (const auto* p = std::get_if<anki::PositionUpdate>(&message)) {
    const bool reverse = state.reverse;
    // A lap whose transition frame was lost: the first report after the line counts it.
    if (p->piece_id == anki::kFinishAfter && currentPieceId() == anki::kFinishBefore && !reverse &&
        !crossedSinceStartPiece_)
      crossFinish(now);
    if (p->piece_id == anki::kFinishBefore) crossedSinceStartPiece_ = false;
    // most reports are from the piece the map has the car on already: no search
    if (!(track_ && index_ && track_->pieces()[*index_].id == p->piece_id)) {
      const bool placing = !index_ && currentPieceId() < 0;
      index_ = locate(p->piece_id, reverse);
      if (placing && index_ && !reverse) placeEarlierTransitions();
      unplaced_.clear();
    }
    lastPieceId_ = p->piece_id;
    // The piece as the track has it (a custom one's shape), else Anki's stock piece of that id.
    if (track_ && index_) {
      fraction_ =
          codeFraction(track_->pieces()[*index_], static_cast<long>(*index_), p->location_id);
    } else {
      const anki::PieceType type = anki::pieceType(p->piece_id);
      const sim::Piece stock{p->piece_id, type, type == anki::PieceType::Curve ? 1 : 0};
      // (a stock piece's key: its id; a curve is a left one here)
      fraction_ = codeFraction(stock, 1000000L + p->piece_id, p->location_id);
    }
    positionTime_ = now;
    // on the start piece: the next transition is the line, whatever the count said
    if (p->piece_id == anki::kFinishBefore && !reverse && lapPieces_ && sinceLine_)
      *sinceLine_ = *lapPieces_ - 1;
  } else if (std::holds_alternative<anki::TransitionUpdate>(message)) {
    transition(state.reverse, now);
  } else if (std::holds_alternative<anki::Delocalized>(message)) {
    index_.reset();
    sinceLine_.reset();
  }
}

double CarTracker::fractionAt(double now, double speed_mm_s, double offset_mm, bool reverse) const {
  if (!track_ || !index_ || positionTime_ < 0 || now <= positionTime_ || speed_mm_s <= 0)
    return fraction_;
  const double length = track_->pieces()[*index_].length(offset_mm);
  if (length <= 0) return fraction_;
  const double moved = speed_mm_s * (now - positionTime_) / length;
  return reverse ? std::max(0.0, fraction_ - moved) : std::min(1.0, fraction_ + moved);
}

// The car has said where it is for the first time, after transitions it made before: walked
// back along the map, one of them may have been the line (34 → 33), crossed then.
void CarTracker::placeEarlierTransitions() {
  const auto& pieces = track_->pieces();
  const std::size_t n = pieces.size();
  const std::size_t k = unplaced_.size();
  for (std::size_t j = 1; j <= k && j < n; ++j) {  // the j-th transition back: into index − j + 1
    const std::size_t into = (*index_ + n * j - (j - 1)) % n;
    const std::size_t from = (into + n - 1) % n;
    if (pieces[from].id == anki::kFinishBefore && pieces[into].id == anki::kFinishAfter) {
      crossFinish(unplaced_[k - j]);
      crossedSinceStartPiece_ = pieces[*index_].id != anki::kFinishBefore;
      return;
    }
  }
}

// The car left the piece it was on: 34 → 33 driving forward is the finish line. Known by the
// piece it was on (reported, or carried on by the map), or — with no map and no position
// update on the start piece — by the number of pieces a lap has, once two laps have shown it.
void CarTracker::transition(bool reverse, double now) {
  if (track_ && !index_ && currentPieceId() < 0 && !reverse &&
      unplaced_.size() < 2 * track_->size())
    unplaced_.push_back(now);
  bool crossed = false;
  if (currentPieceId() == anki::kFinishBefore && !reverse && !crossedSinceStartPiece_) {
    crossed = true;
  } else if (!track_ && !reverse && lapPieces_ && sinceLine_ && *sinceLine_ + 1 == *lapPieces_) {
    crossed = true;  // the pieces of a lap since the last crossing: this is the line
  }
  if (crossed) {
    crossFinish(now);
    // the pieces of one lap, from two crossings in a row that the start piece's reports showed
    if (sinceLine_ && !reverse) {
      const int pieces = *sinceLine_ + 1;
      if (lapPieces_ && *lapPieces_ != pieces)
        lapPieces_.reset();  // a different loop: learn again
      else
        lapPieces_ = pieces;
    }
    sinceLine_ = 0;
  } else if (sinceLine_) {
    ++*sinceLine_;
  }
  if (track_ && index_) {
    const std::size_t n = track_->size();
    index_ = reverse ? (*index_ + n - 1) % n : (*index_ + 1) % n;
    fraction_ = reverse ? 1 : 0;
    positionTime_ = now;
    // carried onto the start piece: the next transition is the line
    if (track_->pieces()[*index_].id == anki::kFinishBefore && !reverse)
      crossedSinceStartPiece_ = false;
  }
  if (reverse) sinceLine_.reset();
}

}  // namespace pitwall::laps
