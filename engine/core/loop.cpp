#include "engine/core/loop.hpp"

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/post.hpp>

namespace pitwall {

Loop::Loop(ClockKind kind) : kind_(kind), wake_(io_), epoch_(std::chrono::steady_clock::now()) {}

TimePoint Loop::realNow() const {
  return std::chrono::duration_cast<TimePoint>(std::chrono::steady_clock::now() - epoch_);
}

Loop::TimerId Loop::at(TimePoint when, Callback fn) {
  TimerId id = nextId_++;
  Key key{when, nextSeq_++};
  timers_.emplace(key, std::make_pair(id, std::move(fn)));
  keys_.emplace(id, key);
  if (kind_ == ClockKind::Real && (!armedFor_ || when < *armedFor_)) armRealTimer();
  return id;
}

bool Loop::cancel(TimerId id) {
  auto it = keys_.find(id);
  if (it == keys_.end()) return false;
  timers_.erase(it->second);
  keys_.erase(it);
  return true;
}

std::optional<TimePoint> Loop::nextDue() const {
  if (timers_.empty()) return std::nullopt;
  return timers_.begin()->first.when;
}

void Loop::post(Callback fn) {
  boost::asio::post(io_, std::move(fn));
}

bool Loop::fireDue() {
  // One bounded batch: the timers due when it began (not those a callback schedules for "now"
  // again), and at most kBatchTimers of them or kBatchTime of real time. Between batches the
  // loop polls signals and sockets, so timer work that never ends (a periodic callback slower
  // than its period) slows itself and never Ctrl-C (docs/safety.md).
  constexpr int kBatchTimers = 256;
  constexpr auto kBatchTime = std::chrono::milliseconds(20);
  const TimePoint t = now();
  // The batch's time limit is real time's only: a virtual run reads no clock here (the read was
  // 15 % of a --fast run's CPU time, docs/performance.md).
  const bool real = kind_ == ClockKind::Real;
  const auto began =
      real ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
  int count = 0;
  while (!stopped_ && !timers_.empty() && timers_.begin()->first.when <= t) {
    auto node = timers_.extract(timers_.begin());
    keys_.erase(node.mapped().first);
    node.mapped().second();
    if (++count >= kBatchTimers) break;
    if (real && std::chrono::steady_clock::now() - began >= kBatchTime) break;
  }
  return count > 0;
}

void Loop::stop() {
  stopped_ = true;
  io_.stop();
}

void Loop::run() {
  stopped_ = false;
  io_.restart();
  if (kind_ == ClockKind::Virtual)
    runVirtual();
  else
    runReal();
}

bool Loop::runAtMost(Duration limit) {
  bool timedOut = false;
  const TimerId deadline = after(limit, [this, &timedOut] {
    timedOut = true;
    stop();
  });
  run();
  cancel(deadline);
  return !timedOut;
}

bool Loop::runUntil(const std::function<bool()>& done, Duration limit) {
  if (done()) return true;
  bool met = false;
  TimerId poll = 0;
  std::function<void()> check = [&] {
    poll = 0;
    if (done()) {
      met = true;
      return stop();
    }
    poll = after(std::chrono::milliseconds(1), check);
  };
  poll = after(std::chrono::milliseconds(1), check);
  runAtMost(limit);
  if (poll) cancel(poll);
  return met;
}

void Loop::runVirtual() {
  // No work guard here: an empty poll() then stops the context and we restart it (a mutex round
  // trip), but with a guard an empty poll() runs the reactor instead — an epoll_wait syscall per
  // pass, measured twice as slow (docs/performance.md).
  while (!stopped_) {
    if (passCheck_) {
      Callback check = passCheck_;  // the check may replace or remove itself
      check();
      if (stopped_) break;
    }
    std::size_t ran = io_.poll();
    if (stopped_) break;
    if (io_.stopped()) io_.restart();
    if (fireDue() || ran > 0) continue;
    // Nothing is ready: jump to the next timer, or end when no timer is left.
    if (timers_.empty()) break;
    virtualNow_ = timers_.begin()->first.when;
  }
}

void Loop::armRealTimer() {
  if (timers_.empty()) {
    armedFor_.reset();
    wake_.cancel();
    return;
  }
  TimePoint when = timers_.begin()->first.when;
  armedFor_ = when;
  wake_.expires_at(epoch_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(when));
  wake_.async_wait([this](const boost::system::error_code& ec) {
    if (ec) return;  // re-armed for an earlier timer, or stopped
    armedFor_.reset();
    fireDue();
    if (!stopped_) armRealTimer();
  });
}

void Loop::runReal() {
  // Keeps run() going while the loop waits for sockets, signals or the next timer.
  auto guard = boost::asio::make_work_guard(io_);
  armRealTimer();
  io_.run();
}

}  // namespace pitwall
