#pragma once
// The `pitwall` subcommands (docs/cli.md). Each returns the process exit status.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pitwall::cli {

struct RunOptions {
  std::string script;
  bool fast = false;
  std::optional<double> duration;  // seconds of engine time
  std::uint64_t seed = 1;
  int cars = 4;
  std::string track = "oval";
  std::string record;  // --record FILE, empty: none
};
int run(const RunOptions& options);

struct TestOptions {
  std::vector<std::string> paths;
  std::uint64_t seed = 1;
  double timeout = 600;  // seconds of virtual time per scenario
};
int test(const TestOptions& options);

int decode(const std::string& protocol, const std::vector<std::string>& hex);
int encode(const std::string& protocol, const std::vector<std::string>& words);

}  // namespace pitwall::cli
