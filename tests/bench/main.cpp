// The benchmark runner: Google Benchmark's own main, with the engine's log quietened so that
// "car 1 connected" lines do not interleave with the figures (see docs/performance.md), and the
// source tree's Lua library. At the end, the table of issue 20's targets (targets.hpp).
#include <benchmark/benchmark.h>

#include <unistd.h>

#include <cstdlib>
#include <cstring>

#include "engine/core/log.hpp"
#include "tests/bench/targets.hpp"

int main(int argc, char** argv) {
  pitwall::log::setLevel(pitwall::log::Level::Warn);
  // The Lua library of the source tree: this binary is not beside a data folder.
  setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 0);
  // The targets table goes with the console format only (--benchmark_format=json or csv get
  // Google Benchmark's own reporter, unchanged); colour only on a terminal. Read before
  // Initialize, which takes the flags out of argv.
  bool console = true;
  for (int i = 1; i < argc; ++i)
    if (std::strncmp(argv[i], "--benchmark_format=", 19) == 0 &&
        std::strcmp(argv[i] + 19, "console") != 0)
      console = false;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (!console) {
    benchmark::RunSpecifiedBenchmarks();
  } else {
    pitwall::bench::TargetReporter reporter(isatty(STDOUT_FILENO)
                                                ? benchmark::ConsoleReporter::OO_Defaults
                                                : benchmark::ConsoleReporter::OO_Tabular);
    benchmark::RunSpecifiedBenchmarks(&reporter);
    reporter.printTargets();
  }
  benchmark::Shutdown();
  return 0;
}
