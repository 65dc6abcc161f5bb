#include "engine/core/warning_limit.hpp"

#include "engine/core/log.hpp"

namespace pitwall {

WarningLimit::WarningLimit(Loop& loop, std::string what, Duration period)
    : loop_(loop), what_(std::move(what)), period_(period) {}

WarningLimit::~WarningLimit() {
  summarise();
  if (timer_) loop_.cancel(timer_);
}

void WarningLimit::warn(const std::string& component, const std::string& message) {
  ++total_;
  component_ = component;
  if (timer_) {  // within a period of the last line: counted
    ++count_;
    latest_ = message;
    return;
  }
  log::warn(component, message);
  timer_ = loop_.after(period_, [this] { tick(); });
}

void WarningLimit::tick() {
  timer_ = 0;
  if (count_ == 0) return;  // a whole period with none: the next is logged in full
  summarise();
  timer_ = loop_.after(period_, [this] { tick(); });
}

void WarningLimit::summarise() {
  if (count_ == 0) return;
  const auto seconds = std::chrono::duration_cast<std::chrono::milliseconds>(period_).count();
  std::string text =
      std::to_string(count_) + " more " + what_ + " in " +
      (seconds % 1000 == 0 ? std::to_string(seconds / 1000) : std::to_string(seconds / 1000.0)) +
      " s; the latest: " + latest_.substr(0, latest_.find('\n'));
  log::warn(component_, text);
  count_ = 0;
}

}  // namespace pitwall
