#pragma once
// Contains a flood of errors from one place (issue 14). A script handler that fails on every
// event would print a traceback per event, dozens a second, and bury everything else in the log.
// The first error from a place is printed in full; those that follow are counted, and once a
// period (a second of engine time: a simulated second in a --fast run) one line says how many
// more there were and what the latest said:
//
//   onPosition handler of car 2 (skull) failed 57 more times: skull.lua:3: no lap yet
//
// After a whole period with no failure from that place, its next error is printed in full again.
// Counts still pending when the flood is flushed (the script shuts down) are logged then, so
// none is lost. It knows nothing of Lua: a place is a name, an error its message.
#include <map>
#include <string>

#include "engine/core/loop.hpp"

namespace pitwall {

class ErrorFlood {
 public:
  // Count lines go to the log at error level, from `component`.
  ErrorFlood(Loop& loop, std::string component, Duration period = std::chrono::seconds(1));
  ~ErrorFlood();  // flushes
  ErrorFlood(const ErrorFlood&) = delete;
  ErrorFlood& operator=(const ErrorFlood&) = delete;

  // An error from `where`: true when the caller should print it in full now, false when it was
  // counted (a count line will say so).
  bool admit(const std::string& where, const std::string& message);
  // Logs every pending count now and forgets every place.
  void flush();

 private:
  struct Place {
    long count = 0;      // errors counted since the last line about this place
    std::string latest;  // the latest of them
    TimePoint last{};    // when the latest error from here came (printed or counted)
    Loop::TimerId tick = 0;
  };
  void tick(const std::string& where);
  void summarise(const std::string& where, Place& place);

  Loop& loop_;
  std::string component_;
  Duration period_;
  std::map<std::string, Place> places_;  // by name: count lines in a stable order
};

}  // namespace pitwall
