#include "engine/core/stop_signals.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

#include <boost/asio/read.hpp>

namespace pitwall {

namespace {

std::atomic<int> g_writeFd{-1};
std::atomic<int> g_count{0};  // signals received
std::atomic<int> g_acted{0};  // signals the loop has acted on
std::atomic<StopSignals::AsyncHook> g_hook{nullptr};
static_assert(std::atomic<int>::is_always_lock_free);

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
    static const char kMsg[] = "\npitwall: the loop did not answer two signals: leaving now\n";
    ssize_t ignored = ::write(STDERR_FILENO, kMsg, sizeof kMsg - 1);
    (void)ignored;
    ::_exit(130);
  }
  int fd = g_writeFd.load(std::memory_order_relaxed);
  if (fd >= 0) {
    char byte = static_cast<char>(sig);
    ssize_t written = ::write(fd, &byte, 1);  // a full pipe already says it
    (void)written;
  }
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
  // count seen ahead of its byte is read on a later pass.
  if (g_count.load(std::memory_order_relaxed) == drained_) return;
  char bytes[16];
  ssize_t n = ::read(pipe_.native_handle(), bytes, sizeof bytes);
  for (ssize_t i = 0; i < n; ++i) {
    ++drained_;
    deliver(static_cast<unsigned char>(bytes[i]));
  }
}

void StopSignals::deliver(int sig) {
  if (sig == SIGINT && sigintReleased_) return;
  int count = g_acted.fetch_add(1, std::memory_order_relaxed) + 1;
  if (onSignal) onSignal(sig, count);
}

}  // namespace pitwall
