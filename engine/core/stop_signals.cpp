#include "engine/core/stop_signals.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

#include <boost/asio/read.hpp>

#include "engine/core/emergency_stops.hpp"

namespace pitwall {

namespace {

std::atomic<int> g_writeFd{-1};
std::atomic<int> g_count{0};  // signals received
std::atomic<int> g_acted{0};  // signals the loop has acted on
std::atomic<StopSignals::AsyncHook> g_hook{nullptr};
std::atomic<int> g_other{0};  // SIGPIPE/SIGTSTP bytes written and not yet read by a virtual loop
static_assert(std::atomic<int>::is_always_lock_free);

// Wakes the loop with the signal's number (a full pipe already says it). `counted`: a stop
// signal, which g_count counts; otherwise g_other keeps a virtual loop reading until it is read.
void tellLoop(int sig, bool counted) {
  int fd = g_writeFd.load(std::memory_order_relaxed);
  if (fd < 0) return;
  if (!counted) g_other.fetch_add(1, std::memory_order_relaxed);
  char byte = static_cast<char>(sig);
  ssize_t written = ::write(fd, &byte, 1);
  (void)written;
}

void onStopSignal(int sig) {
  int saved = errno;
  // A hang-up comes twice or more (the shell passes its own on, the kernel sends one to the
  // foreground group): only a first one counts — a repeat must not make the stop "leave now".
  if (sig == SIGHUP && g_count.load(std::memory_order_relaxed) > 0) {
    errno = saved;
    return;
  }
  int count = g_count.fetch_add(1, std::memory_order_relaxed) + 1;
  if (auto hook = g_hook.load(std::memory_order_relaxed)) hook();
  if (count >= 3 && g_acted.load(std::memory_order_relaxed) < 2) {
    // The last word: every car that can be reached without the loop gets its stop first.
    emergency::sendAll();
    // the stops that need a connection of their own: the watchdog's thread makes them
    emergency::askWatchdog(std::chrono::milliseconds(1500));
    static const char kMsg[] =
        "\npitwall: the loop did not answer two signals: every car sent its stop from outside "
        "the loop; leaving now\n";
    ssize_t ignored = ::write(STDERR_FILENO, kMsg, sizeof kMsg - 1);
    (void)ignored;
    ::_exit(130);
  }
  tellLoop(sig, true);
  errno = saved;
}

// Whether `fd`'s reader has gone: a pipe whose read end closed (head, grep -m1, a quit less)
// polls POLLERR; a socket whose peer left, POLLHUP. Async-signal-safe (poll).
bool readerGone(int fd) {
  struct pollfd p {
    fd, 0, 0
  };
  return ::poll(&p, 1, 0) == 1 && (p.revents & (POLLERR | POLLHUP)) != 0;
}

std::atomic<bool> g_pipeSeen{false};

// SIGPIPE: a write to a reader that went away. Only stdout's and stderr's count: the engine's
// sockets write with MSG_NOSIGNAL and handle EPIPE themselves, and a socket of a library that
// does not is no reason to stop a race. The output that is gone is pointed at /dev/null (the
// rest of the run's output is dropped, never a second signal), the Lua code running is
// interrupted, and the loop is told once. Not a stop signal's count: Ctrl-C after it is still a
// first Ctrl-C.
void onPipe(int) {
  int saved = errno;
  bool out = readerGone(STDOUT_FILENO), err = readerGone(STDERR_FILENO);
  if (out || err) {
    int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (null >= 0) {
      if (out) ::dup2(null, STDOUT_FILENO);
      if (err) ::dup2(null, STDERR_FILENO);
      ::close(null);
    }
    if (!g_pipeSeen.exchange(true, std::memory_order_relaxed)) {
      if (auto hook = g_hook.load(std::memory_order_relaxed)) hook();
      tellLoop(SIGPIPE, false);
    }
  }
  errno = saved;
}

// SIGTSTP (Ctrl-Z): the loop stops the cars and then suspends the process itself (SIGSTOP); the
// handler only tells it. Not a stop signal's count either.
void onSuspend(int) {
  int saved = errno;
  tellLoop(SIGTSTP, false);
  errno = saved;
}

}  // namespace

StopSignals::StopSignals(Loop& loop) : loop_(loop), pipe_(loop.io()) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC | O_NONBLOCK) != 0)
    throw std::runtime_error(std::string("cannot make the signal pipe: ") + std::strerror(errno));
  pipe_.assign(fds[0]);
  writeFd_ = fds[1];
  g_count.store(0, std::memory_order_relaxed);
  g_acted.store(0, std::memory_order_relaxed);
  g_writeFd.store(writeFd_, std::memory_order_relaxed);
  struct sigaction sa {};
  sa.sa_handler = onStopSignal;
  sigemptyset(&sa.sa_mask);
  // No SA_RESTART: a script blocked in a read (a FIFO, the terminal) gets EINTR and returns to the
  // loop, which then acts on the signal; the engine's own I/O is asynchronous and retries.
  sa.sa_flags = 0;
  ::sigaction(SIGINT, &sa, &oldInt_);
  ::sigaction(SIGTERM, &sa, &oldTerm_);
  // SIGHUP: the terminal closed (a window shut, an SSH connection dropped). Its default action
  // ends the process on the spot — no stop for any car, the terminal's modes not put back — so
  // it ends the run as SIGTERM does. (nohup's SIG_IGN is kept: the run was meant to outlive
  // its terminal.)
  ::sigaction(SIGHUP, nullptr, &oldHup_);
  hupCaught_ = oldHup_.sa_handler != SIG_IGN;
  if (hupCaught_) ::sigaction(SIGHUP, &sa, nullptr);
  // SIGPIPE's default action ends the process with every car at its speed: `pitwall run … |
  // head` must end through the stop path instead.
  g_pipeSeen.store(false, std::memory_order_relaxed);
  g_other.store(0, std::memory_order_relaxed);
  struct sigaction pipe {};
  pipe.sa_handler = onPipe;
  sigemptyset(&pipe.sa_mask);
  ::sigaction(SIGPIPE, &pipe, &oldPipe_);
  // SIGTSTP's default action freezes the loop with the cars at speed. Kept ignored when it was
  // ignored at start (a shell without job control).
  ::sigaction(SIGTSTP, nullptr, &oldTstp_);
  tstpCaught_ = oldTstp_.sa_handler != SIG_IGN;
  if (tstpCaught_) {
    struct sigaction tstp {};
    tstp.sa_handler = onSuspend;
    sigemptyset(&tstp.sa_mask);
    ::sigaction(SIGTSTP, &tstp, nullptr);
  }
  if (loop.clockKind() == ClockKind::Virtual)
    loop.setPassCheck([this] { drain(); });
  else
    await();
}

StopSignals::~StopSignals() {
  if (loop_.clockKind() == ClockKind::Virtual) loop_.setPassCheck({});
  if (!sigintReleased_) ::sigaction(SIGINT, &oldInt_, nullptr);
  ::sigaction(SIGTERM, &oldTerm_, nullptr);
  if (hupCaught_) ::sigaction(SIGHUP, &oldHup_, nullptr);
  ::sigaction(SIGPIPE, &oldPipe_, nullptr);
  if (tstpCaught_) ::sigaction(SIGTSTP, &oldTstp_, nullptr);
  g_writeFd.store(-1, std::memory_order_relaxed);
  boost::system::error_code ignored;
  pipe_.close(ignored);
  ::close(writeFd_);
}

void StopSignals::setAsyncHook(AsyncHook hook) {
  g_hook.store(hook, std::memory_order_relaxed);
}

void StopSignals::releaseSigint() {
  sigintReleased_ = true;
}

void StopSignals::await() {
  pipe_.async_read_some(boost::asio::buffer(&byte_, 1),
                        [this](const boost::system::error_code& ec, std::size_t n) {
                          if (ec || n == 0) return;
                          await();
                          deliver(static_cast<unsigned char>(byte_));
                        });
}

void StopSignals::drain() {
  // One relaxed load per pass while no signal came; the handler counts before it writes, so a
  // count seen ahead of its byte is read on a later pass. SIGPIPE and SIGTSTP are not counted:
  // their bytes are read by the next read of the pipe, so a virtual run reads once per pass
  // while it has not had them all (an unanswered read costs a syscall, and only in that case).
  if (g_count.load(std::memory_order_relaxed) == drained_ &&
      !g_other.load(std::memory_order_relaxed))
    return;
  char bytes[16];
  ssize_t n = ::read(pipe_.native_handle(), bytes, sizeof bytes);
  for (ssize_t i = 0; i < n; ++i) {
    int sig = static_cast<unsigned char>(bytes[i]);
    if (sig == SIGPIPE || sig == SIGTSTP)
      g_other.fetch_sub(1, std::memory_order_relaxed);
    else
      ++drained_;
    deliver(sig);
  }
}

void StopSignals::deliver(int sig) {
  if (sig == SIGINT && sigintReleased_) return;
  if (sig == SIGPIPE || sig == SIGTSTP) {  // neither counts towards "leave now"
    if (onSignal) onSignal(sig, 0);
    return;
  }
  int count = g_acted.fetch_add(1, std::memory_order_relaxed) + 1;
  if (onSignal) onSignal(sig, count);
}

}  // namespace pitwall
