#pragma once
// The targets of issue 20 as a table at the end of a benchmark run (`./dev bench`): each figure
// with its target and whether it is met, computed from the runs of this same invocation (a
// ratio is always against a floor measured in the same run). A target whose benchmarks did not
// run (filtered out, or skipped with an error) says so.
#include <benchmark/benchmark.h>

#include <map>
#include <string>
#include <vector>

namespace pitwall::bench {

// Shows the runs as the console reporter does, and keeps their counters for the table.
class TargetReporter : public benchmark::ConsoleReporter {
 public:
  explicit TargetReporter(OutputOptions options) : ConsoleReporter(options) {}
  void ReportRuns(const std::vector<Run>& runs) override;
  // The table, printed after RunSpecifiedBenchmarks.
  void printTargets() const;

 private:
  struct Figures {
    double realSeconds = 0;  // per iteration
    std::map<std::string, double> counters;
  };
  const Figures* find(const std::string& name) const;
  std::map<std::string, Figures> runs_;  // by run name; the median when there are repetitions
};

}  // namespace pitwall::bench
