#include "engine/record/record_player.hpp"

#include <algorithm>

namespace pitwall {

namespace {
// Frames recorded within a microsecond of a position are due at it (the record's resolution;
// a loop time rounds to nanoseconds).
constexpr double kResolution = 1e-6;
}  // namespace

RecordPlayer::RecordPlayer(Loop& loop, Fleet& fleet, std::vector<RecordedFrame> frames)
    : loop_(loop), fleet_(fleet), frames_(std::move(frames)) {
  times_.reserve(frames_.size());
  double last = 0;
  for (const auto& f : frames_) {
    last = std::max(last, f.t);
    times_.push_back(last);
    cars_[f.car];
  }
  std::map<int, std::string> names;  // as the record keeps them (a car's first line)
  for (const auto& f : frames_)
    if (!f.name.empty()) names.emplace(f.car, f.name);
  for (auto& [number, c] : cars_) {
    numbers_.push_back(number);
    auto link = std::make_unique<ReplayLink>("car " + std::to_string(number));
    c.link = link.get();
    CarIdentity identity;
    auto named = names.find(number);
    identity.name = named != names.end() ? named->second : "car" + std::to_string(number);
    c.car = &fleet_.add(std::move(link), identity);
  }
  for (const auto& f : frames_)
    if (f.tx) ++cars_[f.car].framesOut;
  for (auto& [number, c] : cars_) c.link->connect();
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
    for (auto& [number, c] : cars_) c.car->rewind();
    next_ = 0;
  }
  deliverUpTo(target);
  anchor(target);
  schedule();
}

void RecordPlayer::deliver(std::size_t index) {
  const RecordedFrame& f = frames_[index];
  if (f.tx) return;
  delivering_ = times_[index];
  cars_[f.car].link->deliver(f.bytes);
  delivering_.reset();
}

void RecordPlayer::deliverUpTo(double position) {
  const bool wasEnded = ended();
  while (next_ < frames_.size() && times_[next_] <= position + kResolution) deliver(next_++);
  if (ended() && !wasEnded && onEnd) onEnd();
}

void RecordPlayer::schedule() {
  if (timer_) loop_.cancel(timer_);
  timer_ = 0;
  if (!playing_ || paused_ || ended()) return;
  const double wait = std::max(0.0, (times_[next_] - anchorPos_) / speed_);
  timer_ = loop_.at(anchorLoop_ + fromSeconds(wait), [this] {
    timer_ = 0;
    // at least the frame this timer was for: a loop time rounded to nanoseconds may lie a hair
    // before the frame's time
    deliverUpTo(std::max(elapsedPosition(), times_[next_]));
    schedule();
  });
}

}  // namespace pitwall
