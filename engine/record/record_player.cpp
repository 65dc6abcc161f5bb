#include "engine/record/record_player.hpp"

#include <algorithm>
#include <chrono>

#include "engine/protocol/anki/codec.hpp"

namespace pitwall {

namespace {
// Frames recorded within a microsecond of a position are due at it (the record's resolution;
// a loop time rounds to nanoseconds).
constexpr double kResolution = 1e-6;
constexpr auto kSlice = std::chrono::milliseconds(20);
// Lines read for one frame before the loop turns: a few milliseconds of bad lines (about 5 µs a
// line), so a record with a million of them in a row holds no callback long.
constexpr std::size_t kLinesPerRead = 4096;
}  // namespace

RecordPlayer::RecordPlayer(Loop& loop, Fleet& fleet, std::istream& in, const RecordSummary& summary)
    : loop_(loop), fleet_(fleet), stream_(in, 0), duration_(summary.duration) {
  for (const auto& [number, out] : summary.framesOut) {
    numbers_.push_back(number);
    Car& c = cars_[number];
    c.framesOut = out;
    auto link = std::make_unique<ReplayLink>("car " + std::to_string(number));
    c.link = link.get();
    CarIdentity identity;
    auto named = summary.names.find(number);
    identity.name = named != summary.names.end() ? named->second : "car" + std::to_string(number);
    c.car = &fleet_.add(std::move(link), identity);
  }
  for (auto& [number, c] : cars_) c.link->connect();
  stream_.rewind();
  readNext();
}

RecordPlayer::~RecordPlayer() {
  if (timer_) loop_.cancel(timer_);
}

AnkiCar* RecordPlayer::car(int recorded) const {
  auto it = cars_.find(recorded);
  return it == cars_.end() ? nullptr : it->second.car;
}

std::uint64_t RecordPlayer::framesOut(int recorded) const {
  auto it = cars_.find(recorded);
  return it == cars_.end() ? 0 : it->second.framesOut;
}

double RecordPlayer::elapsedPosition() const {
  if (ended()) return duration();
  if (!playing_ || paused_) return anchorPos_;
  return anchorPos_ + toSeconds(loop_.now() - anchorLoop_) * speed_;
}

double RecordPlayer::position() const {
  if (delivering_) return *delivering_;
  if (seekTarget_) return caught_;  // a seek under way: as far as it has come
  return std::clamp(elapsedPosition(), 0.0, duration());
}

void RecordPlayer::anchor(double position) {
  anchorPos_ = position;
  anchorLoop_ = loop_.now();
}

void RecordPlayer::play() {
  playing_ = true;
  anchor(0);
  schedule();
}

void RecordPlayer::pause(bool paused) {
  if (paused == paused_) return;
  anchor(position());
  paused_ = paused;
  schedule();
}

void RecordPlayer::setSpeed(double speed) {
  if (!(speed > 0)) return;
  anchor(position());
  speed_ = speed;
  schedule();
}

void RecordPlayer::seek(double seconds) {
  double target = std::clamp(seconds, 0.0, duration());
  if (target < position()) {
    if (onRewind) onRewind();
    for (auto& [number, c] : cars_) {
      c.link->rewind();
      c.car->rewind();
    }
    stream_.rewind();
    reading_ = false;
    ++readGeneration_;
    nextTime_ = 0;
    caught_ = 0;
    readNext();
  }
  if (!seekTarget_) seekWasEnded_ = ended();
  seekTarget_ = target;
  ++seekGeneration_;
  if (timer_) loop_.cancel(timer_);
  timer_ = 0;
  catchUp();
}

// The frames up to a seek's target, delivered at once — in slices on the real clock: at most
// kSlice of work, then the loop turns (the view answers, signals are acted on, the watchdog
// hears from it) and the next slice follows. A seek across a million frames took seconds of one
// callback (docs/safety.md: the loop turns at least every 100 ms).
void RecordPlayer::catchUp() {
  if (!seekTarget_) return;
  const bool sliced = loop_.clockKind() == ClockKind::Real;
  const auto until = std::chrono::steady_clock::now() + kSlice;
  std::size_t n = 0;
  while (next_ && nextTime_ <= *seekTarget_ + kResolution) {
    deliverNext();
    if (reading_) return;  // readOn goes on with the seek
    if (sliced && (++n % 256) == 0 && std::chrono::steady_clock::now() >= until) {
      std::weak_ptr<bool> alive = alive_;
      loop_.post([this, alive, generation = seekGeneration_] {
        if (!alive.expired() && generation == seekGeneration_) catchUp();
      });
      return;
    }
  }
  if (reading_) return;  // readOn goes on with the seek
  const double target = *seekTarget_;
  seekTarget_.reset();
  if (ended() && !seekWasEnded_ && onEnd) onEnd();
  anchor(target);
  schedule();
}

void RecordPlayer::readNext() {
  next_ = stream_.next(kLinesPerRead);
  if (next_) {
    nextTime_ = std::max(nextTime_, next_->t);
    return;
  }
  if (stream_.done() || reading_) return;
  reading_ = true;
  std::weak_ptr<bool> alive = alive_;
  loop_.post([this, alive, generation = readGeneration_] {
    if (!alive.expired() && generation == readGeneration_) readOn();
  });
}

void RecordPlayer::readOn() {
  reading_ = false;
  readNext();
  if (reading_) return;  // more bad lines: after the loop has turned again
  if (seekTarget_) return catchUp();
  if (ended() && playing_ && onEnd) onEnd();  // the bad lines ran to the end of the file
  schedule();
}

void RecordPlayer::deliverNext() {
  const RecordedFrame f = std::move(*next_);
  const double time = nextTime_;
  readNext();
  if (f.car == 0) {  // the race as it was at that time
    if (onRace) {
      delivering_ = time;
      onRace(f.race);
      delivering_.reset();
    }
    return;
  }
  auto c = cars_.find(f.car);  // a car the summary did not see: the file changed since
  if (c == cars_.end()) return;
  if (f.link) {  // the link went up or down then
    delivering_ = time;
    c->second.link->recorded(f.link->up, f.link->reason,
                             {f.link->writeFailures, f.link->stalls, f.link->rssi});
    delivering_.reset();
    return;
  }
  if (f.tx) {  // what the run sent: told, never sent again
    if (onSent) {
      if (auto decoded = anki::decode(f.bytes)) onSent(*c->second.car, *decoded);
    }
    return;
  }
  caught_ = time;
  delivering_ = time;
  c->second.link->deliver(f.bytes);
  delivering_.reset();
}

void RecordPlayer::deliverUpTo(double position) {
  const bool wasEnded = ended();
  while (next_ && nextTime_ <= position + kResolution) deliverNext();
  if (ended() && !wasEnded && onEnd) onEnd();
}

void RecordPlayer::schedule() {
  if (timer_) loop_.cancel(timer_);
  timer_ = 0;
  // a seek schedules when done, and so does a read that goes on
  if (!playing_ || paused_ || !next_ || seekTarget_) return;
  const double wait = std::max(0.0, (nextTime_ - anchorPos_) / speed_);
  timer_ = loop_.at(anchorLoop_ + fromSeconds(wait), [this] {
    timer_ = 0;
    // at least the frame this timer was for: a loop time rounded to nanoseconds may lie a hair
    // before the frame's time
    deliverUpTo(std::max(elapsedPosition(), nextTime_));
    schedule();
  });
}

}  // namespace pitwall
