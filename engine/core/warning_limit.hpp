#pragma once
// Rate-limits one kind of warning from one source (issue 33): a car or link that sends nothing
// but malformed frames would write a warning per frame — hundreds a second from a hostile peer —
// and bury everything else in the log. The first warning is logged in full; those that follow
// are counted, and once a period (5 s of engine time by default) one line says how many more
// there were and what the latest said:
//
//   warn car 2 (skull): 412 more malformed frames ignored in 5 s; the latest: too short: …
//
// After a whole period with none, the next is logged in full again. A count still pending when
// the limit goes (its car is removed) is logged then, so none is lost. ErrorFlood
// (error_flood.hpp) does the same for script errors from many places; this is one place, and
// warnings.
#include <string>

#include "engine/core/loop.hpp"

namespace pitwall {

class WarningLimit {
 public:
  // `what` names what is counted, in the plural: "malformed frames ignored".
  WarningLimit(Loop& loop, std::string what, Duration period = std::chrono::seconds(5));
  ~WarningLimit();  // logs a pending count
  WarningLimit(const WarningLimit&) = delete;
  WarningLimit& operator=(const WarningLimit&) = delete;

  // A warning from `component` (a car's label: it may change as the car is named).
  void warn(const std::string& component, const std::string& message);
  // Warnings counted and not yet said, and all of them so far.
  long pending() const { return count_; }
  long total() const { return total_; }

 private:
  void tick();
  void summarise();

  Loop& loop_;
  std::string what_;
  Duration period_;
  std::string component_, latest_;
  long count_ = 0, total_ = 0;
  Loop::TimerId timer_ = 0;  // while a window is open: the end of this period
};

}  // namespace pitwall
