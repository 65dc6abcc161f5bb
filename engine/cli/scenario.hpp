#pragma once
// One scenario test (pitwall test): a *_test.lua file run in a world of its own in virtual time,
// and what became of it, in the pieces every report needs (docs/testing.md).
#include <cstdint>
#include <string>
#include <vector>

namespace pitwall::cli {

struct ScenarioSettings {
  std::uint64_t seed = 1;
  double timeout = 600;        // seconds of virtual time
  bool libraryFrames = false;  // --verbose: tracebacks list the library's frames too
  double budget = 0.1;         // --budget: seconds of CPU time a callback may use; 0: off
  int luaMemory = 512;         // --lua-memory: MB the scenario's world may hold; 0: no limit
};

struct ScenarioResult {
  enum class Status { Passed, Failed, Errored, TimedOut, Crashed };
  Status status = Status::Passed;
  // The failure in a sentence or a few lines: "stuck_test.lua:5: speed: expected 700, got 500".
  std::string message;
  std::string file;  // where the failure is in the test's own file (empty: not there)
  int line = 0;
  std::vector<std::string> traceback;  // the frames, as Lua lists them
  std::vector<std::string> waiting;    // a stuck scenario: where each task waits…
  double stoppedAt = 0;                // …when it was stopped (virtual seconds)
  double simulated = 0;                // seconds of virtual time
  double wall = 0;                     // seconds of real time
  std::uint64_t seed = 1;
  std::string output;  // what it printed, when run in a process of its own
  std::string data;    // what a job hands its parent besides (a league heat's results as JSON)

  bool passed() const { return status == Status::Passed; }
};

// Runs `file` in this process.
ScenarioResult runScenario(const std::string& file, const ScenarioSettings& settings);

// Splits a host failure ("error in main chunk: a.lua:5: msg\nstack traceback:\n\t…") into the
// message, its traceback and the innermost frame in `testFile`.
void readFailure(const std::string& failure, const std::string& testFile, ScenarioResult& into);

}  // namespace pitwall::cli
