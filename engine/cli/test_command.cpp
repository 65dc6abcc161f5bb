// pitwall test [PATH…]: scenario scripts in virtual time, each in a world of its own.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>

#include "bindings/interrupt.hpp"
#include "bindings/sandbox.hpp"
#include "engine/cli/commands.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/session.hpp"
#include "engine/core/log.hpp"

namespace pitwall::cli {

namespace fs = std::filesystem;

namespace {

// A folder runs every *_test.lua below it, in name order.
Result<std::vector<std::string>, std::string> collect(const std::vector<std::string>& paths) {
  std::vector<std::string> files;
  for (const auto& p : paths) {
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      std::vector<std::string> found;
      for (const auto& e : fs::recursive_directory_iterator(p, ec)) {
        std::string name = e.path().filename().string();
        if (e.is_regular_file() && name.size() > 9 && name.ends_with("_test.lua"))
          found.push_back(e.path().string());
      }
      std::sort(found.begin(), found.end());
      if (found.empty()) return Unexpected{"no *_test.lua files in " + p};
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::is_regular_file(p, ec)) {
      files.push_back(p);
    } else {
      return Unexpected{"cannot open " + p + ": no such file or folder"};
    }
  }
  return files;
}

struct Outcome {
  bool passed = false;
  std::string message;
  double simulated = 0;
};

Outcome runScenario(const std::string& file, const TestOptions& options) {
  Outcome out;
  auto track = sim::namedLayout("oval");
  Session session(ClockKind::Virtual, std::move(*track), options.seed);
  HostOptions host;
  host.test_mode = true;
  host.seed = options.seed;
  try {
    session.startHost(host);
  } catch (const std::exception& e) {
    out.message = e.what();
    return out;
  }
  Loop& loop = session.loop();
  bool timedOut = false;
  loop.after(fromSeconds(options.timeout), [&] {
    timedOut = true;
    session.finish();
  });
  auto started = session.host().startFile(file);
  if (!started) {
    out.message = started.error();
    return out;
  }
  loop.run();  // ends through Session::finish, which every way out of a run calls
  out.simulated = loop.seconds();
  if (auto& failure = session.host().failure()) {
    out.message = *failure;
  } else if (timedOut && !session.host().mainFinished()) {
    out.message = "still running after " + std::to_string(static_cast<int>(options.timeout)) +
                  " s of virtual time (raise it with --timeout)";
  } else {
    out.passed = true;
  }
  return out;
}

}  // namespace

int test(const TestOptions& options) {
  auto files = collect(options.paths);
  if (!files) {
    std::cerr << "pitwall test: " << files.error() << "\n";
    return 2;
  }
  interrupt::setBudget(std::chrono::milliseconds(std::lround(options.budget * 1000)));
  sandbox::setMemoryLimit(static_cast<std::size_t>(options.luaMemory) << 20);
  int passed = 0, failed = 0;
  for (const auto& file : *files) {
    auto begin = std::chrono::steady_clock::now();
    Outcome o = runScenario(file, options);
    double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    char timing[96];
    std::snprintf(timing, sizeof timing, "(%.1f s simulated in %.0f ms)", o.simulated, wall * 1000);
    if (o.passed) {
      ++passed;
      std::cout << "ok    " << file << " " << timing << "\n";
    } else {
      ++failed;
      std::cout << "FAIL  " << file << " " << timing << "\n      " << o.message << "\n";
    }
    std::cout.flush();
  }
  std::cout << passed << " passed, " << failed << " failed\n";
  return failed ? 1 : 0;
}

Command addTestCommand(CLI::App& app) {
  auto test = std::make_shared<TestOptions>();
  auto* cmd = app.add_subcommand("test", "Run scenario test scripts in virtual time");
  cmd->add_option("paths", test->paths, "Scenario files, or folders of *_test.lua files");
  cmd->add_option("--seed", test->seed, "Seed of the simulator's and the scripts' randomness");
  cmd->add_option("--timeout", test->timeout, "Virtual seconds a scenario may run (default 600)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--budget", test->budget,
                  "Seconds of CPU time a callback may use before it is interrupted (default 0.1; "
                  "0: no limit)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--lua-memory", test->luaMemory,
                  "MB of memory a scenario's Lua world may hold (default 512; 0: no limit)")
      ->check(CLI::Range(0, 1 << 20));
  return {cmd,
          [test] {
            if (test->paths.empty()) test->paths.push_back("tests/scenarios");
            return cli::test(*test);
          },
          /*quiet=*/true};
}

}  // namespace pitwall::cli
