#include "engine/cli/test_pool.hpp"

#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

namespace pitwall::cli {

namespace {

// The result crosses from the child in a file: numbers and length-prefixed strings.
class Writer {
 public:
  explicit Writer(std::FILE* f) : f_(f) {}
  void number(double v) { std::fwrite(&v, sizeof v, 1, f_); }
  void text(const std::string& s) {
    number(static_cast<double>(s.size()));
    std::fwrite(s.data(), 1, s.size(), f_);
  }
  void texts(const std::vector<std::string>& v) {
    number(static_cast<double>(v.size()));
    for (const auto& s : v) text(s);
  }

 private:
  std::FILE* f_;
};

class Reader {
 public:
  explicit Reader(std::FILE* f) : f_(f) {}
  bool ok() const { return ok_; }
  double number() {
    double v = 0;
    if (std::fread(&v, sizeof v, 1, f_) != 1) ok_ = false;
    return v;
  }
  std::string text() {
    double n = number();
    if (!ok_ || n < 0 || n > 64e6) return ok_ = false, "";
    std::string s(static_cast<std::size_t>(n), '\0');
    if (std::fread(s.data(), 1, s.size(), f_) != s.size()) ok_ = false;
    return s;
  }
  std::vector<std::string> texts() {
    double n = number();
    std::vector<std::string> v;
    for (double i = 0; ok_ && i < n && i < 1e6; ++i) v.push_back(text());
    return v;
  }

 private:
  std::FILE* f_;
  bool ok_ = true;
};

void save(std::FILE* f, const ScenarioResult& r) {
  Writer w(f);
  w.number(static_cast<double>(r.status));
  w.text(r.message);
  w.text(r.file);
  w.number(r.line);
  w.texts(r.traceback);
  w.texts(r.waiting);
  w.number(r.stoppedAt);
  w.number(r.simulated);
  w.number(r.wall);
  w.text(std::to_string(r.seed));
  w.text(r.data);
}

std::optional<ScenarioResult> load(std::FILE* f) {
  std::rewind(f);
  Reader rd(f);
  ScenarioResult r;
  int status = static_cast<int>(rd.number());
  r.message = rd.text();
  r.file = rd.text();
  r.line = static_cast<int>(rd.number());
  r.traceback = rd.texts();
  r.waiting = rd.texts();
  r.stoppedAt = rd.number();
  r.simulated = rd.number();
  r.wall = rd.number();
  std::string seed = rd.text();
  r.data = rd.text();
  if (!rd.ok() || status < 0 || status > static_cast<int>(ScenarioResult::Status::Crashed))
    return std::nullopt;
  r.status = static_cast<ScenarioResult::Status>(status);
  r.seed = std::strtoull(seed.c_str(), nullptr, 10);
  return r;
}

std::string readAll(std::FILE* f) {
  std::rewind(f);
  std::string out;
  char buf[8192];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.append(buf, n);
  return out;
}

struct Child {
  std::size_t index;
  std::FILE* output;
  std::FILE* result;
};

}  // namespace

int availableCores() {
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1u, std::thread::hardware_concurrency());
}

void runInProcesses(std::size_t count, int jobs,
                    const std::function<ScenarioResult(std::size_t)>& run,
                    const std::function<void(std::size_t, ScenarioResult)>& report) {
  std::map<pid_t, Child> running;
  std::map<std::size_t, ScenarioResult> done;  // ended, waiting for those before them
  std::size_t next = 0, reported = 0;
  auto start = [&](std::size_t i) {
    Child c{i, std::tmpfile(), std::tmpfile()};
    if (!c.output || !c.result)
      throw std::runtime_error(std::string("tmpfile: ") + strerror(errno));
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    pid_t pid = fork();
    if (pid < 0) throw std::runtime_error(std::string("fork: ") + strerror(errno));
    if (pid == 0) {
      dup2(fileno(c.output), STDOUT_FILENO);
      dup2(fileno(c.output), STDERR_FILENO);
      // Line by line, as on a terminal: what it printed just before a crash is kept.
      std::setvbuf(stdout, nullptr, _IOLBF, 0);
      ScenarioResult r = run(i);
      std::cout.flush();
      std::cerr.flush();
      std::fflush(nullptr);
      save(c.result, r);
      std::fflush(c.result);
      _exit(0);  // no destructors, no atexit handlers: they are the parent's
    }
    running.emplace(pid, c);
  };
  while (reported < count) {
    while (next < count && static_cast<int>(running.size()) < jobs) start(next++);
    int status = 0;
    pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(std::string("waitpid: ") + strerror(errno));
    }
    auto it = running.find(pid);
    if (it == running.end()) continue;  // not one of ours
    Child c = it->second;
    running.erase(it);
    std::optional<ScenarioResult> r;
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) r = load(c.result);
    if (!r) {
      r.emplace();
      r->status = ScenarioResult::Status::Crashed;
      if (WIFSIGNALED(status))
        r->message = "the scenario's process crashed: signal " + std::to_string(WTERMSIG(status)) +
                     " (" + strsignal(WTERMSIG(status)) + ")";
      else
        r->message = "the scenario's process ended with status " +
                     std::to_string(WEXITSTATUS(status)) + " without a result";
    }
    r->output = readAll(c.output);
    std::fclose(c.output);
    std::fclose(c.result);
    done.emplace(c.index, std::move(*r));
    for (auto d = done.find(reported); d != done.end(); d = done.find(reported)) {
      report(reported, std::move(d->second));
      done.erase(d);
      ++reported;
    }
  }
}

}  // namespace pitwall::cli
