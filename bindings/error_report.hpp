#pragma once
// A world's script errors, one of ScriptHost's jobs (bindings/script_host.hpp): an error in a
// callback is handed to pitwall.onError when the script set one, else logged with its traceback —
// a place that keeps failing prints one traceback, then a count line a second
// (engine/core/error_flood.hpp); in test mode the first is the scenario's failure. An error in a
// car's handler also counts towards stopping that car (CarBinding::handlerFailed). Reaching the
// memory cap is said once and ends the run.
#include <optional>
#include <string>

#include "engine/core/error_flood.hpp"

namespace pitwall {

class ScriptHost;

class ErrorReport {
 public:
  explicit ErrorReport(ScriptHost& host);

  // An error of `where` ("onPosition handler of car 1 (skull)"): reported as above.
  void report(const std::string& where, const std::string& message);
  // After a failed call: when the memory cap was reached, says so once and asks the run to end
  // with exit status 1.
  void checkMemory();
  // Logs the counts not yet logged (the world shuts down): none is lost.
  void flush() { flood_.flush(); }
  // In test mode: the first failure (an error in a task or callback, a failed expectation).
  const std::optional<std::string>& failure() const { return failure_; }
  int count() const { return count_; }

 private:
  ScriptHost& host_;
  ErrorFlood flood_;
  std::optional<std::string> failure_;
  int count_ = 0;
  bool inOnError_ = false;  // pitwall.onError is running: an error of its own goes to the log
  bool memoryReported_ = false;
};

}  // namespace pitwall
