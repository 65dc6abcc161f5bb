// The benchmark runner: Google Benchmark's own main, with the engine's log quietened so that
// "car 1 connected" lines do not interleave with the figures (see docs/performance.md), and the
// source tree's Lua library. At the end, the table of issue 20's targets (targets.hpp).
#include <benchmark/benchmark.h>

#include <cstdlib>

#include "engine/core/log.hpp"
#include "tests/bench/targets.hpp"

int main(int argc, char** argv) {
  pitwall::log::setLevel(pitwall::log::Level::Warn);
  // The Lua library of the source tree: this binary is not beside a data folder.
  setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 0);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  pitwall::bench::TargetReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.printTargets();
  benchmark::Shutdown();
  return 0;
}
