#pragma once
// What `pitwall test` prints and writes about its scenarios (docs/testing.md, "Reports"): lines
// for a person, TAP 14 for a TAP consumer, JUnit XML for CI systems (GitLab, Jenkins, GitHub
// annotations).
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "engine/cli/scenario.hpp"

namespace pitwall::cli {

struct ReportedScenario {
  std::string path;  // as collected: the file the test is
  ScenarioResult result;
  std::string replay;  // the command that runs it again as it ran (its seed, the run's options)
};

// The person's report of one scenario: its output, `ok`/`FAIL` with the failure, the test's line,
// the traceback when it says more, where a stuck scenario's tasks wait, how to replay it.
void printScenario(std::ostream& out, const ReportedScenario& s, bool verbose);

// TAP 14: the plan first, then one test point per scenario as it ends (what it printed as
// comments); failures carry a YAML block (message, at: file and line, seed, durations).
void printTapPlan(std::ostream& out, std::size_t count);
void printTapPoint(std::ostream& out, std::size_t number, const ReportedScenario& s);

// One <testsuite> of one <testcase> per scenario: classname the folder, name the file's stem,
// file and line of the failure, time in seconds; <failure> for a failed expectation, <error>
// for any other error, a stuck run or a crash; what it printed in <system-out>.
void writeJUnit(std::ostream& out, const std::vector<ReportedScenario>& scenarios,
                double wallSeconds);

}  // namespace pitwall::cli
