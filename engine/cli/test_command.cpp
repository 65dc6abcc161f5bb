// pitwall test [PATH…]: scenario scripts in virtual time, each in a world and a process of its
// own: which ones (--filter, --list), how many at once (-j), and the reports (docs/testing.md).
#include <fnmatch.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <random>
#include <sstream>

#include "engine/cli/commands.hpp"
#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/scenario.hpp"
#include "engine/cli/test_pool.hpp"
#include "engine/cli/test_report.hpp"
#include "engine/core/printable.hpp"
#include "engine/core/result.hpp"
#include "engine/core/suggest.hpp"

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

// A scenario's tags: `-- tags: race reload` in the comment block at the top of its file.
std::vector<std::string> tagsOf(const std::string& file) {
  std::vector<std::string> tags;
  std::ifstream in(file);
  std::string line;
  for (int n = 0; n < 50 && std::getline(in, line); ++n) {
    auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos) continue;
    if (line.compare(first, 2, "--") != 0) break;  // the code begins
    auto text = line.find_first_not_of("- \t", first);
    if (text == std::string::npos || line.compare(text, 5, "tags:") != 0) continue;
    std::istringstream words(line.substr(text + 5));
    for (std::string w; words >> w;) {
      while (!w.empty() && w.back() == ',') w.pop_back();
      if (!w.empty()) tags.push_back(w);
    }
  }
  return tags;
}

struct Scenario {
  std::string path;
  std::string name;  // the file's stem: ping_test
  std::vector<std::string> tags;
};

bool hasWildcard(const std::string& p) {
  return p.find_first_of("*?[") != std::string::npos;
}

// --filter PATTERN: a glob (fnmatch) matched against the path, the name and each tag; without
// wildcards, a part of the name or a whole tag.
bool matches(const Scenario& s, const std::string& pattern) {
  if (hasWildcard(pattern)) {
    auto glob = [&](const std::string& text) {
      return fnmatch(pattern.c_str(), text.c_str(), 0) == 0;
    };
    if (glob(s.path) || glob(s.name)) return true;
    return std::any_of(s.tags.begin(), s.tags.end(), glob);
  }
  if (s.name.find(pattern) != std::string::npos) return true;
  return std::find(s.tags.begin(), s.tags.end(), pattern) != s.tags.end();
}

Result<std::vector<Scenario>, std::string> select(const std::vector<std::string>& files,
                                                  const std::vector<std::string>& filters) {
  std::vector<Scenario> all, chosen;
  for (const auto& f : files) all.push_back({f, fs::path(f).stem().string(), tagsOf(f)});
  if (filters.empty()) return all;
  for (const auto& p : filters)
    if (p.empty())
      return Unexpected{
          std::string("--filter \"\": an empty pattern matches every scenario; "
                      "leave --filter out to run them all")};
  for (const auto& s : all)
    if (std::any_of(filters.begin(), filters.end(), [&](const auto& p) { return matches(s, p); }))
      chosen.push_back(s);
  if (!chosen.empty()) return chosen;
  std::vector<std::string> names;
  for (const auto& s : all) {
    names.push_back(s.name);
    for (const auto& t : s.tags)
      if (std::find(names.begin(), names.end(), t) == names.end()) names.push_back(t);
  }
  std::string text = "--filter " + printable(filters.front(), 80);
  for (std::size_t i = 1; i < filters.size(); ++i) text += ", " + printable(filters[i], 80);
  text += (filters.size() > 1 ? " match none of the " : " matches none of the ") +
          std::to_string(all.size()) + (all.size() == 1 ? " scenario" : " scenarios");
  for (const auto& p : filters) {
    std::string hint = hasWildcard(p) ? "" : didYouMean(p, names);
    if (hint.empty()) continue;
    text += filters.size() > 1
                ? hint.substr(0, hint.size() - 1) + " (for " + printable(p, 80) + ")?"
                : hint;
    break;
  }
  return Unexpected{text + " (pitwall test --list shows their names and tags)"};
}

// --seed N: every scenario runs with N; --seed random: each with a seed of its own, drawn now
// and printed with its failure.
Result<std::vector<std::uint64_t>, std::string> seedsFor(const std::string& option,
                                                         std::size_t count) {
  if (option == "random") {
    std::random_device device;
    std::vector<std::uint64_t> seeds;
    for (std::size_t i = 0; i < count; ++i)
      seeds.push_back((static_cast<std::uint64_t>(device()) << 32 | device()) % 1'000'000'000);
    return seeds;
  }
  std::uint64_t seed = 0;
  auto [end, ec] = std::from_chars(option.data(), option.data() + option.size(), seed);
  if (ec != std::errc() || end != option.data() + option.size() || option.empty())
    return Unexpected{"--seed " + printable(option, 40) +
                      ": expected a whole number from 0 to 18446744073709551615, or random"};
  return std::vector<std::uint64_t>(count, seed);
}

// A path as a shell reads it: as it is when it has only safe characters, else in single quotes.
std::string shellQuoted(const std::string& text) {
  if (!text.empty() && text.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                              "0123456789_-./+,:=@%") == std::string::npos)
    return text;
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// The options besides the seed that change how a scenario runs, when not their defaults.
std::string runOptions(const TestOptions& o) {
  const TestOptions defaults;
  std::string out;
  auto number = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return std::string(text);
  };
  if (o.timeout != defaults.timeout) out += " --timeout " + number(o.timeout);
  if (o.budget != defaults.budget) out += " --budget " + number(o.budget);
  if (o.luaMemory != defaults.luaMemory) out += " --lua-memory " + std::to_string(o.luaMemory);
  if (o.verbose) out += " --verbose";
  return out;
}

}  // namespace

int test(const TestOptions& options) {
  auto files = collect(options.paths);
  if (!files) {
    return fail("test", files.error());
  }
  auto scenarios = select(*files, options.filters);
  if (!scenarios) {
    return fail("test", scenarios.error());
  }
  if (options.list) {
    for (const auto& s : *scenarios) {
      std::cout << s.path;
      if (!s.tags.empty()) {
        std::cout << "  [";
        for (std::size_t i = 0; i < s.tags.size(); ++i) std::cout << (i ? " " : "") << s.tags[i];
        std::cout << "]";
      }
      std::cout << "\n";
    }
    return 0;
  }
  auto seeds = seedsFor(options.seed, scenarios->size());
  if (!seeds) {
    return fail("test", seeds.error());
  }
  std::ofstream junit;
  if (!options.junit.empty()) {
    junit.open(options.junit, std::ios::trunc);
    if (!junit) {
      return fail("test", "--junit " + printable(options.junit, 200) +
                              ": cannot write the file: " + std::strerror(errno));
    }
  }
  int jobs = options.jobs > 0 ? options.jobs : availableCores();

  std::vector<ReportedScenario> reported;
  int passed = 0, failed = 0;
  auto begin = std::chrono::steady_clock::now();
  if (options.tap) printTapPlan(std::cout, scenarios->size());
  runInProcesses(
      scenarios->size(), jobs,
      [&](std::size_t i) {
        ScenarioSettings settings;
        settings.seed = (*seeds)[i];
        settings.timeout = options.timeout;
        settings.libraryFrames = options.verbose;
        settings.budget = options.budget;
        settings.luaMemory = options.luaMemory;
        return runScenario((*scenarios)[i].path, settings);
      },
      [&](std::size_t i, ScenarioResult result) {
        result.seed = (*seeds)[i];
        std::string again = "pitwall test " + shellQuoted((*scenarios)[i].path) + " --seed " +
                            std::to_string((*seeds)[i]) + runOptions(options);
        reported.push_back({(*scenarios)[i].path, std::move(result), std::move(again)});
        const ReportedScenario& s = reported.back();
        (s.result.passed() ? passed : failed)++;
        if (options.tap)
          printTapPoint(std::cout, i + 1, s);
        else
          printScenario(std::cout, s, options.verbose);
      });
  double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  if (options.tap)
    std::cout << "# " << passed << " passed, " << failed << " failed\n";
  else
    std::cout << passed << " passed, " << failed << " failed\n";
  if (junit.is_open()) {
    writeJUnit(junit, reported, wall);
    junit.close();
    if (!junit) {
      return fail("test",
                  "--junit " + printable(options.junit, 200) + ": the report could not be written");
    }
  }
  return failed ? 1 : 0;
}

Command addTestCommand(CLI::App& app) {
  auto test = std::make_shared<TestOptions>();
  auto* cmd = app.add_subcommand("test", "Run scenario test scripts in virtual time");
  cmd->add_option("paths", test->paths, "Scenario files, or folders of *_test.lua files");
  cmd->add_option("--seed", test->seed,
                  "Seed of the simulator's and the scripts' randomness: N for every scenario "
                  "(default 1), or random for a seed of its own each, printed with a failure");
  cmd->add_option("--filter", test->filters,
                  "Only the scenarios whose name or tag matches PATTERN: a part of the name, a "
                  "whole tag, or a glob on name, path or tag ('race_*'); may be given more than "
                  "once")
      ->type_name("PATTERN");
  cmd->add_flag("--list", test->list,
                "List the scenarios (with --filter: those chosen) and their tags; run none");
  cmd->add_option(
         "-j,--jobs", test->jobs,
         "Scenarios run at once, each in a process of its own (default: the number of cores)")
      ->check(CLI::Range(1, 256));
  cmd->add_option("--junit", test->junit, "Also write the results as JUnit XML to FILE (for CI)")
      ->type_name("FILE");
  cmd->add_flag("--tap", test->tap, "Print the results as TAP 14 instead of lines for a person");
  cmd->add_flag("-v,--verbose", test->verbose,
                "Tracebacks list the library's frames too (scripts/pitwall/) and C functions");
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
