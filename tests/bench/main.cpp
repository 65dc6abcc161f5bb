// The benchmark runner: Google Benchmark's own main, with the engine's log quietened so that
// "car 1 connected" lines do not interleave with the figures (see docs/performance.md).
#include <benchmark/benchmark.h>

#include "engine/core/log.hpp"

int main(int argc, char** argv) {
  pitwall::log::setLevel(pitwall::log::Level::Warn);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
