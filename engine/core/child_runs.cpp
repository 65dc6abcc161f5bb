#include "engine/core/child_runs.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/steady_timer.hpp>
#include <cerrno>
#include <cstring>

extern char** environ;

namespace pitwall {

namespace asio = boost::asio;

struct ChildRuns::Job {
  Job(asio::io_context& io) : out(io), err(io), clock(io), reap(io) {}
  std::vector<std::string> argv;
  Done done;
  ChildOutcome outcome;
  pid_t pid = -1;
  asio::posix::stream_descriptor out, err;
  asio::steady_timer clock, reap;
  std::array<char, 16384> bufOut{}, bufErr{};
  int open = 0;  // pipes not at their end yet
  bool ended = false;
  std::chrono::steady_clock::time_point queuedAt, startedAt;

  void kill() {
    if (pid > 0) ::kill(-pid, SIGKILL);
  }
};

ChildRuns::ChildRuns(Loop& loop, ChildLimits limits) : loop_(loop), limits_(limits) {}

ChildRuns::~ChildRuns() {
  *alive_ = false;
  queue_.clear();
  for (auto& w : live_)
    if (auto job = w.lock()) {
      job->kill();
      if (job->pid > 0) ::waitpid(job->pid, nullptr, 0);
      job->pid = -1;
      boost::system::error_code ignored;
      job->out.close(ignored);
      job->err.close(ignored);
      job->clock.cancel();
      job->reap.cancel();
    }
}

bool ChildRuns::run(std::vector<std::string> argv, Done done) {
  if (queue_.size() >= limits_.queue) return false;
  auto job = std::make_shared<Job>(loop_.io());
  job->argv = std::move(argv);
  job->done = std::move(done);
  job->queuedAt = std::chrono::steady_clock::now();
  queue_.push_back(std::move(job));
  startNext();
  return true;
}

void ChildRuns::startNext() {
  while (running_ < static_cast<std::size_t>(std::max(1, limits_.parallel)) && !queue_.empty()) {
    auto job = std::move(queue_.front());
    queue_.pop_front();
    start(std::move(job));
  }
}

namespace {

// A pipe's read end as a stream the loop reads; the write end dup'ed onto `target` in the child.
bool makePipe(int fds[2]) {
  return ::pipe2(fds, O_CLOEXEC) == 0;
}

}  // namespace

void ChildRuns::start(std::shared_ptr<Job> job) {
  job->startedAt = std::chrono::steady_clock::now();
  job->outcome.waited = std::chrono::duration<double>(job->startedAt - job->queuedAt).count();
  int outPipe[2] = {-1, -1}, errPipe[2] = {-1, -1};
  auto failed = [&](const std::string& why) {
    for (int fd : {outPipe[0], outPipe[1], errPipe[0], errPipe[1]})
      if (fd >= 0) ::close(fd);
    job->outcome.failure = why;
    loop_.post([job, alive = alive_] {
      if (*alive) job->done(std::move(job->outcome));
    });
  };
  if (!makePipe(outPipe) || !makePipe(errPipe))
    return failed(std::string("cannot make a pipe: ") + std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawnattr_t attr;
  posix_spawn_file_actions_init(&actions);
  posix_spawnattr_init(&attr);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, outPipe[1], 1);
  posix_spawn_file_actions_adddup2(&actions, errPipe[1], 2);
  // nothing else of the run's: its listening socket, browsers, links (Boost.Asio opens sockets
  // without close-on-exec) — a child that outlived the run would hold the view's port
  posix_spawn_file_actions_addclosefrom_np(&actions, 3);
  // its own process group (a terminal's Ctrl-C is the run's; a kill reaches all it started),
  // no signal blocked and none ignored (the run ignores SIGPIPE: a child should not)
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  for (int s : {SIGPIPE, SIGINT, SIGTERM, SIGTSTP, SIGHUP, SIGQUIT}) sigaddset(&defaults, s);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawnattr_setflags(&attr,
                           POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  std::vector<char*> args;
  for (auto& a : job->argv) args.push_back(a.data());
  args.push_back(nullptr);
  pid_t pid = -1;
  int rc =
      args.size() > 1 ? posix_spawn(&pid, args[0], &actions, &attr, args.data(), environ) : EINVAL;
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  ::close(outPipe[1]);
  ::close(errPipe[1]);
  outPipe[1] = errPipe[1] = -1;
  if (rc != 0)
    return failed("cannot start " + (job->argv.empty() ? std::string("nothing") : job->argv[0]) +
                  ": " + std::strerror(rc));
  job->pid = pid;
  errno = 0;
  const int base = ::getpriority(PRIO_PROCESS, 0);
  if (limits_.nice > 0) ::setpriority(PRIO_PROCESS, static_cast<id_t>(pid), base + limits_.nice);
  job->out.assign(outPipe[0]);
  job->err.assign(errPipe[0]);
  job->open = 2;
  running_++;
  live_.push_back(job);
  std::erase_if(live_, [](const auto& w) { return w.expired(); });

  // reads one pipe to its end, into `into`, cut at the cap
  auto read = [this, job](asio::posix::stream_descriptor& pipe, std::array<char, 16384>& buf,
                          std::string& into, auto& self) -> void {
    pipe.async_read_some(asio::buffer(buf), [this, job, &pipe, &buf, &into, self, alive = alive_](
                                                boost::system::error_code ec, std::size_t n) {
      if (!*alive) return;
      if (!ec) {
        const std::size_t room = limits_.maxOutput - std::min(limits_.maxOutput, into.size());
        into.append(buf.data(), std::min(n, room));
        if (n > room && !job->outcome.tooLong) {
          job->outcome.tooLong = true;
          job->kill();
        }
        return self(pipe, buf, into, self);
      }
      if (--job->open == 0) finished(job);
    });
  };
  read(job->out, job->bufOut, job->outcome.out, read);
  read(job->err, job->bufErr, job->outcome.err, read);
  job->clock.expires_after(limits_.timeout);
  job->clock.async_wait([job, alive = alive_](boost::system::error_code ec) {
    if (ec || !*alive || job->ended) return;
    job->outcome.timedOut = true;
    job->kill();
    // whatever still holds the pipes (a process that left the group) is not waited for: a
    // second later they are closed, the reads end and the child is reaped
    job->clock.expires_after(std::chrono::seconds(1));
    job->clock.async_wait([job, alive](boost::system::error_code e) {
      if (e || !*alive || job->ended) return;
      boost::system::error_code ignored;
      job->out.cancel(ignored);
      job->err.cancel(ignored);
    });
  });
}

// Both pipes are at their end: the child is reaped (it may close them a moment before it exits).
void ChildRuns::finished(const std::shared_ptr<Job>& job) {
  int st = 0;
  pid_t got = ::waitpid(job->pid, &st, WNOHANG);
  if (got == 0) {
    job->reap.expires_after(std::chrono::milliseconds(5));
    job->reap.async_wait([this, job, alive = alive_](boost::system::error_code ec) {
      if (!ec && *alive) finished(job);
    });
    return;
  }
  job->ended = true;
  job->clock.cancel();
  job->pid = -1;
  if (got > 0 && WIFEXITED(st)) job->outcome.status = WEXITSTATUS(st);
  if (got > 0 && WIFSIGNALED(st)) job->outcome.signal = WTERMSIG(st);
  job->outcome.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - job->startedAt).count();
  running_--;
  boost::system::error_code ignored;
  job->out.close(ignored);
  job->err.close(ignored);
  auto done = std::move(job->done);
  done(std::move(job->outcome));
  startNext();
}

}  // namespace pitwall
