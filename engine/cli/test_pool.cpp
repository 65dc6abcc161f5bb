#include "engine/cli/test_pool.hpp"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

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

// What a child that ended without a result left of one.
ScenarioResult crashed(int status) {
  ScenarioResult r;
  r.status = ScenarioResult::Status::Crashed;
  if (WIFSIGNALED(status))
    r.message = "the scenario's process crashed: signal " + std::to_string(WTERMSIG(status)) +
                " (" + strsignal(WTERMSIG(status)) + ")";
  else
    r.message = "the scenario's process ended with status " + std::to_string(WEXITSTATUS(status)) +
                " without a result";
  return r;
}

// Everything printed so far written out (before a fork, or before the output moves).
void flushAll() {
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
}

// fork() with nothing buffered twice; throws when it fails.
pid_t forkFlushed() {
  flushAll();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + strerror(errno));
  return pid;
}

// From now on this process prints (stdout and stderr) to `fd`, line by line as on a terminal:
// what it printed just before a crash is kept.
void printTo(int fd) {
  dup2(fd, STDOUT_FILENO);
  dup2(fd, STDERR_FILENO);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
}

// Hands results to report() in order: each as soon as it and every one before it are in.
class InOrder {
 public:
  explicit InOrder(const std::function<void(std::size_t, ScenarioResult)>& report)
      : report_(report) {}
  void add(std::size_t index, ScenarioResult r) {
    done_.emplace(index, std::move(r));
    for (auto d = done_.find(reported_); d != done_.end(); d = done_.find(reported_)) {
      report_(reported_, std::move(d->second));
      done_.erase(d);
      ++reported_;
    }
  }
  std::size_t reported() const { return reported_; }

 private:
  const std::function<void(std::size_t, ScenarioResult)>& report_;
  std::map<std::size_t, ScenarioResult> done_;  // ended, waiting for those before them
  std::size_t reported_ = 0;
};

// A task's index through a pipe, whole (EINTR retried): read, or written; false at the pipe's
// end or on an error.
bool moveIndex(int fd, std::uint64_t& index, bool writing) {
  auto* p = reinterpret_cast<char*>(&index);
  std::size_t left = sizeof index;
  while (left > 0) {
    const ssize_t n = writing ? ::write(fd, p, left) : ::read(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  return true;
}

// Writes a task's index to a worker; false when the worker is gone (EPIPE: the SIGPIPE that
// write raises is blocked and taken back, the parent's own handling of it left as it is).
bool sendTask(int fd, std::uint64_t index) {
  sigset_t pipeSignal, old;
  sigemptyset(&pipeSignal);
  sigaddset(&pipeSignal, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipeSignal, &old);
  const bool ok = moveIndex(fd, index, true);
  if (!ok && errno == EPIPE) {
    const timespec now{};
    while (sigtimedwait(&pipeSignal, nullptr, &now) < 0 && errno == EINTR) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  return ok;
}

// A worker of runInWorkers: a child that runs the tasks its parent sends (an index on `tasks`)
// one after the other, each with its output in DIR/INDEX.out and its result in DIR/INDEX.res,
// and answers with the index on `done`. Ends at the end of `tasks`.
[[noreturn]] void work(int tasks, int done, const std::string& dir,
                       const std::function<ScenarioResult(std::size_t)>& run) {
  std::uint64_t index = 0;
  while (moveIndex(tasks, index, false)) {
    const std::string base = dir + "/" + std::to_string(index);
    flushAll();
    int out = ::open((base + ".out").c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (out < 0) _exit(3);
    printTo(out);
    ::close(out);
    // (an exception is this task's error: unwinding past here would run the parent's code)
    ScenarioResult r;
    try {
      r = run(static_cast<std::size_t>(index));
    } catch (const std::exception& e) {
      r.status = ScenarioResult::Status::Errored;
      r.message = e.what();
    } catch (...) {
      r.status = ScenarioResult::Status::Errored;
      r.message = "an unknown exception";
    }
    flushAll();
    std::FILE* res = std::fopen((base + ".res").c_str(), "wb");
    if (!res) _exit(3);
    save(res, r);
    if (std::fclose(res) != 0 || !moveIndex(done, index, true)) _exit(3);
  }
  _exit(0);  // no destructors, no atexit handlers: they are the parent's
}

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
  InOrder inOrder(report);
  std::size_t next = 0;
  auto start = [&](std::size_t i) {
    Child c{i, std::tmpfile(), std::tmpfile()};
    if (!c.output || !c.result)
      throw std::runtime_error(std::string("tmpfile: ") + strerror(errno));
    const pid_t pid = forkFlushed();
    if (pid == 0) {
      printTo(fileno(c.output));
      ScenarioResult r = run(i);
      flushAll();
      save(c.result, r);
      std::fflush(c.result);
      _exit(0);  // no destructors, no atexit handlers: they are the parent's
    }
    running.emplace(pid, c);
  };
  while (inOrder.reported() < count) {
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
    if (!r) r = crashed(status);
    r->output = readAll(c.output);
    std::fclose(c.output);
    std::fclose(c.result);
    inOrder.add(c.index, std::move(*r));
  }
}

void runInWorkers(std::size_t count, int jobs,
                  const std::function<ScenarioResult(std::size_t)>& run,
                  const std::function<void(std::size_t, ScenarioResult)>& report) {
  namespace fs = std::filesystem;
  std::string pattern = (fs::temp_directory_path() / "pitwall-workers-XXXXXX").string();
  if (!::mkdtemp(pattern.data()))
    throw std::runtime_error(std::string("mkdtemp: ") + strerror(errno));
  const std::string dir = pattern;
  struct Worker {
    pid_t pid = -1;
    int tasks = -1, done = -1;  // the parent's ends of its two pipes
    std::optional<std::size_t> task;
  };
  std::vector<Worker> workers;
  auto spawn = [&] {
    int tasks[2], done[2];
    if (::pipe2(tasks, O_CLOEXEC) != 0)
      throw std::runtime_error(std::string("pipe: ") + strerror(errno));
    if (::pipe2(done, O_CLOEXEC) != 0) {
      const int error = errno;
      ::close(tasks[0]);
      ::close(tasks[1]);
      throw std::runtime_error(std::string("pipe: ") + strerror(error));
    }
    const pid_t pid = forkFlushed();
    if (pid == 0) {
      for (const Worker& w : workers) {  // (the others' pipes are not this one's)
        ::close(w.tasks);
        ::close(w.done);
      }
      ::close(tasks[1]);
      ::close(done[0]);
      work(tasks[0], done[1], dir, run);
    }
    ::close(tasks[0]);
    ::close(done[1]);
    workers.push_back(Worker{pid, tasks[1], done[0], std::nullopt});
  };
  auto file = [&](std::size_t index, const char* ext) {
    return dir + "/" + std::to_string(index) + ext;
  };
  // What a task left: its output, and its result or (none) what its worker's end says.
  auto collect = [&](std::size_t index, int status) {
    std::optional<ScenarioResult> r;
    if (std::FILE* res = std::fopen(file(index, ".res").c_str(), "rb")) {
      r = load(res);
      std::fclose(res);
    }
    if (!r) r = crashed(status);
    if (std::FILE* out = std::fopen(file(index, ".out").c_str(), "rb")) {
      r->output = readAll(out);
      std::fclose(out);
    }
    std::remove(file(index, ".out").c_str());
    std::remove(file(index, ".res").c_str());
    return std::move(*r);
  };
  // The end: the workers told there is nothing more (or, `now`, stopped), waited for; the folder
  // gone.
  auto finish = [&](bool now) {
    for (Worker& w : workers) {
      ::close(w.tasks);
      if (now) ::kill(w.pid, SIGKILL);
    }
    for (Worker& w : workers) {
      ::close(w.done);
      int status = 0;
      while (::waitpid(w.pid, &status, 0) < 0 && errno == EINTR) {
      }
    }
    workers.clear();
    std::error_code ec;
    fs::remove_all(dir, ec);
  };
  InOrder inOrder(report);
  std::size_t next = 0;
  auto give = [&](Worker& w) {
    if (next >= count) return;
    const std::uint64_t index = next++;
    w.task = static_cast<std::size_t>(index);
    if (!sendTask(w.tasks, index)) {  // (gone: poll sees its end, and a new worker takes it)
      w.task.reset();
      --next;
    }
  };
  try {
    for (int j = 0; j < jobs && static_cast<std::size_t>(j) < count; ++j) spawn();
    for (Worker& w : workers) give(w);
    while (inOrder.reported() < count) {
      std::vector<pollfd> fds;
      for (const Worker& w : workers) fds.push_back(pollfd{w.done, POLLIN, 0});
      if (::poll(fds.data(), fds.size(), -1) < 0) {
        if (errno == EINTR) continue;
        throw std::runtime_error(std::string("poll: ") + strerror(errno));
      }
      for (std::size_t k = 0; k < workers.size(); ++k) {
        if (!fds[k].revents) continue;
        Worker& w = workers[k];
        std::uint64_t index = 0;
        if (moveIndex(w.done, index, false) && w.task && index == *w.task) {
          w.task.reset();
          inOrder.add(static_cast<std::size_t>(index), collect(index, 0));
          give(w);
          continue;
        }
        // Its end: it crashed (its task too) — or the pipe broke, and it goes (it may be alive).
        // A new worker takes over.
        ::close(w.tasks);
        ::close(w.done);
        ::kill(w.pid, SIGKILL);
        int status = 0;
        while (::waitpid(w.pid, &status, 0) < 0 && errno == EINTR) {
        }
        const std::optional<std::size_t> lost = w.task;
        workers.erase(workers.begin() + static_cast<std::ptrdiff_t>(k));
        if (lost) inOrder.add(*lost, collect(*lost, status));
        if (next < count) {
          spawn();
          give(workers.back());
        }
        break;  // (the list changed: poll again)
      }
    }
  } catch (...) {
    finish(true);
    throw;
  }
  finish(false);
}

}  // namespace pitwall::cli
