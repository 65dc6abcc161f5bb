// runInWorkers (engine/cli/test_pool.hpp): a league's heats in `jobs` children forked once, each
// running task after task; a child that dies is one failed task, and the tasks go on.
#include "engine/cli/test_pool.hpp"

#include <doctest/doctest.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

using namespace pitwall::cli;
namespace fs = std::filesystem;

namespace {

// TMPDIR of its own while it lives (runInWorkers makes its folder there), removed after.
struct OwnTemp {
  fs::path dir;
  std::string old;
  bool had = false;
  OwnTemp() {
    std::string pattern = (fs::temp_directory_path() / "pool-test-XXXXXX").string();
    REQUIRE(::mkdtemp(pattern.data()) != nullptr);
    dir = pattern;
    if (const char* t = std::getenv("TMPDIR")) had = true, old = t;
    ::setenv("TMPDIR", dir.c_str(), 1);
  }
  ~OwnTemp() {
    if (had)
      ::setenv("TMPDIR", old.c_str(), 1);
    else
      ::unsetenv("TMPDIR");
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  bool empty() const { return fs::is_empty(dir); }
};

struct Reported {
  std::vector<std::size_t> order;
  std::vector<ScenarioResult> results;
};

Reported runAll(std::size_t count, int jobs,
                const std::function<ScenarioResult(std::size_t)>& run) {
  Reported r;
  runInWorkers(count, jobs, run, [&](std::size_t i, ScenarioResult result) {
    r.order.push_back(i);
    r.results.push_back(std::move(result));
  });
  return r;
}

}  // namespace

TEST_CASE("runInWorkers: every task once, reported in order, by children that run many") {
  OwnTemp temp;
  const pid_t parent = ::getpid();
  Reported r = runAll(9, 2, [](std::size_t i) {
    std::printf("task %zu printed this\n", i);
    ScenarioResult out;
    out.data = std::to_string(::getpid());
    out.simulated = static_cast<double>(i) * 10;
    if (i == 4) {
      out.status = ScenarioResult::Status::Failed;
      out.message = "task 4 failed, as a task may";
    }
    return out;
  });
  REQUIRE(r.order.size() == 9);
  std::set<std::string> pids;
  for (std::size_t i = 0; i < 9; ++i) {
    CHECK(r.order[i] == i);
    CHECK(r.results[i].simulated == static_cast<double>(i) * 10);
    CHECK(r.results[i].output == "task " + std::to_string(i) + " printed this\n");
    CHECK(r.results[i].data != std::to_string(parent));  // (run in a child)
    pids.insert(r.results[i].data);
  }
  CHECK(r.results[4].status == ScenarioResult::Status::Failed);
  CHECK(r.results[4].message == "task 4 failed, as a task may");
  CHECK(pids.size() <= 2);  // two children ran the nine tasks: no fork per task
  CHECK(temp.empty());      // its folder and every task's files are gone
}

TEST_CASE(
    "runInWorkers: a child that dies is its task's failure, with what it printed; the rest run") {
  OwnTemp temp;
  Reported r = runAll(7, 2, [](std::size_t i) {
    std::printf("task %zu begins\n", i);
    if (i == 2 || i == 5) {
      std::fflush(stdout);
      ::raise(SIGKILL);
    }
    return ScenarioResult{};
  });
  REQUIRE(r.order.size() == 7);
  for (std::size_t i = 0; i < 7; ++i) {
    CHECK(r.order[i] == i);
    CHECK(r.results[i].output == "task " + std::to_string(i) + " begins\n");
    if (i == 2 || i == 5) {
      CHECK(r.results[i].status == ScenarioResult::Status::Crashed);
      CHECK(r.results[i].message.find("signal 9") != std::string::npos);
    } else {
      CHECK(r.results[i].passed());
    }
  }
  CHECK(temp.empty());
}

TEST_CASE("runInWorkers: a task that throws is its own error; its child runs the next ones") {
  OwnTemp temp;
  Reported r = runAll(4, 1, [](std::size_t i) -> ScenarioResult {
    if (i == 1) throw std::runtime_error("task 1 threw");
    ScenarioResult out;
    out.data = std::to_string(::getpid());
    return out;
  });
  REQUIRE(r.order.size() == 4);
  CHECK(r.results[1].status == ScenarioResult::Status::Errored);
  CHECK(r.results[1].message == "task 1 threw");
  CHECK(r.results[0].passed());
  CHECK(r.results[3].passed());
  CHECK(r.results[0].data == r.results[3].data);  // the same child before and after
  CHECK(temp.empty());
}

TEST_CASE("runInWorkers: no tasks, and more children asked for than tasks") {
  OwnTemp temp;
  CHECK(runAll(0, 4, [](std::size_t) { return ScenarioResult{}; }).order.empty());
  Reported r = runAll(2, 8, [](std::size_t i) {
    ScenarioResult out;
    out.data = std::to_string(i * i);
    return out;
  });
  REQUIRE(r.order.size() == 2);
  CHECK(r.results[1].data == "1");
  CHECK(temp.empty());
}
