#include "engine/core/lag_monitor.hpp"

#include <algorithm>

namespace pitwall {

LagMonitor::LagMonitor(Loop& loop) : loop_(loop) {
  started_ = loop_.now();
  due_ = loop_.now() + kPeriod;
  timer_ = loop_.at(due_, [this] { sample(); });
}

LagMonitor::~LagMonitor() {
  loop_.cancel(timer_);
}

void LagMonitor::sample() {
  const TimePoint now = loop_.now();
  // one stall counts at most kStallMs: a suspended run (Ctrl-Z) resumed is no lasting lag, and a
  // stuck loop is the watchdog's business
  const double late = std::clamp(toSeconds(now - due_) * 1000, 0.0, kStallMs);
  lateMs_.emplace_back(now, late);
  while (!lateMs_.empty() && lateMs_.front().first < now - kWindow) lateMs_.pop_front();
  // the next on the grid after now: a stall counts once, not once for every period it held
  due_ = std::max(due_ + kPeriod, now + kPeriod / 2);
  timer_ = loop_.at(due_, [this] { sample(); });
  if (now - started_ < kWindow) return;
  double sum = 0;
  for (const auto& s : lateMs_) sum += s.second;
  const double mean = sum / static_cast<double>(lateMs_.size());
  if (!behind_ && mean > kBehindMs) {
    behind_ = true;
    if (onBehind) onBehind(mean);
  } else if (behind_ && mean < kCaughtUpMs) {
    behind_ = false;
    if (onCaughtUp) onCaughtUp();
  }
}

}  // namespace pitwall
