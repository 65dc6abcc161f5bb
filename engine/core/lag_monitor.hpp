#pragma once
// Whether a real-time loop keeps up with the wall clock (docs/simulator.md "Real time"): a
// timer of its own every 13 ms (a period no script's timer shares, so the two cannot lock in
// step) notes how late it ran. When its lateness over the last 2 s averages more than two
// simulator ticks (10 ms), the engine has fallen behind real time — a script's long callbacks,
// a loaded machine — and onBehind says so, with that mean, once until the mean is below 5 ms
// again (then onCaughtUp).
#include <chrono>
#include <deque>
#include <functional>
#include <utility>

#include "engine/core/loop.hpp"

namespace pitwall {

class LagMonitor {
 public:
  explicit LagMonitor(Loop& loop);
  ~LagMonitor();
  LagMonitor(const LagMonitor&) = delete;
  LagMonitor& operator=(const LagMonitor&) = delete;

  std::function<void(double meanLateMs)> onBehind;
  std::function<void()> onCaughtUp;
  bool behind() const { return behind_; }

  static constexpr Duration kPeriod = std::chrono::milliseconds(13);
  static constexpr double kBehindMs = 10;  // two ticks
  static constexpr double kCaughtUpMs = 5;
  static constexpr double kStallMs = 250;  // the most one sample counts
  static constexpr Duration kWindow = std::chrono::seconds(2);

 private:
  void sample();

  Loop& loop_;
  Loop::TimerId timer_ = 0;
  TimePoint due_{0};
  // the samples of the last kWindow (when, how late): a held loop samples less often, so the
  // window is one of time, not of a number of samples
  std::deque<std::pair<TimePoint, double>> lateMs_;
  TimePoint started_{0};
  bool behind_ = false;
};

}  // namespace pitwall
