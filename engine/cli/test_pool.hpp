#pragma once
// Scenarios in processes of their own (pitwall test -j N): each runs in a child of this process,
// its output and its result in files of its own, so scenarios cannot disturb each other and a
// crash is one failed scenario; results are handed on in the order of the scenarios. A league's
// heats run the same way in children that each run many (runInWorkers).
#include <cstddef>
#include <functional>

#include "engine/cli/scenario.hpp"

namespace pitwall::cli {

// The number of cores this process may run on.
int availableCores();

// Runs run(i) for i in [0, count) in up to `jobs` child processes at once and calls report(i,
// result) in the parent for i = 0, 1, … in that order, each as soon as it and every one before
// it have ended; result.output holds what the child printed. The parent must have no threads
// of its own (it forks).
void runInProcesses(std::size_t count, int jobs,
                    const std::function<ScenarioResult(std::size_t)>& run,
                    const std::function<void(std::size_t, ScenarioResult)>& report);

// The same with `jobs` children forked once, each running task after task (a league's heats: a
// fork, a process's fresh pages and its end per task cost a heat 12 % more CPU,
// docs/performance.md): run(i) must leave its process as it found it. A child that crashes is
// one failed task — what it printed kept — and a new child takes the tasks left. Each task's
// output and result go through files of its own in a temporary folder, gone at the end.
void runInWorkers(std::size_t count, int jobs,
                  const std::function<ScenarioResult(std::size_t)>& run,
                  const std::function<void(std::size_t, ScenarioResult)>& report);

}  // namespace pitwall::cli
