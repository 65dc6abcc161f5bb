#include "engine/record/recorder.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>

#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/protocol/anki/message_json.hpp"
#include "engine/record/record_reader.hpp"

namespace pitwall {

namespace {

constexpr auto kFlushEvery = std::chrono::milliseconds(50);  // half the promise: margin

// The recorder a crash handler flushes (one per process: the run's).
std::atomic<int> g_fd{-1};
std::atomic<const char*> g_buffer{nullptr};
std::atomic<std::size_t> g_used{0};

bool writeAll(int fd, const char* data, std::size_t n) {
  while (n > 0) {
    ssize_t w = ::write(fd, data, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

// A crash: what is buffered (whole lines) goes to the file, then the signal does what it does.
void onCrash(int sig) {
  int fd = g_fd.load(std::memory_order_relaxed);
  const char* buffer = g_buffer.load(std::memory_order_relaxed);
  std::size_t used = g_used.load(std::memory_order_relaxed);
  if (fd >= 0 && buffer && used > 0) writeAll(fd, buffer, used);
  g_used.store(0, std::memory_order_relaxed);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

void catchCrashes() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int sig : {SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT}) {
      struct sigaction sa {};
      sa.sa_handler = onCrash;
      sigemptyset(&sa.sa_mask);
      sa.sa_flags = SA_RESETHAND;
      struct sigaction old {};
      ::sigaction(sig, nullptr, &old);
      if (old.sa_handler == SIG_DFL) ::sigaction(sig, &sa, nullptr);  // sanitizers keep theirs
    }
  });
}

}  // namespace

Recorder::Recorder(const std::string& path)
    : path_(path), buffer_(new char[kCapacity]), lastFlush_(std::chrono::steady_clock::now()) {
  try {
    open();
  } catch (...) {
    delete[] buffer_;
    throw;
  }
}

Recorder::Recorder(const std::string& path, Later)
    : path_(path), buffer_(new char[kCapacity]), lastFlush_(std::chrono::steady_clock::now()) {
  // Would open() succeed? A file that is there must be writable (and not a folder); one that is
  // not needs a writable folder. Nothing is created or truncated here.
  std::string why;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode))
      why = std::strerror(EISDIR);
    else if (::access(path.c_str(), W_OK) != 0)
      why = std::strerror(errno);
  } else if (errno == ENOENT) {
    auto slash = path.rfind('/');
    std::string folder = slash == std::string::npos ? "."
                         : slash == 0               ? "/"
                                                    : path.substr(0, slash);
    if (::access(folder.c_str(), W_OK | X_OK) != 0) why = std::strerror(errno);
  } else {
    why = std::strerror(errno);
  }
  if (!why.empty()) {
    delete[] buffer_;
    throw std::runtime_error("cannot open record file " + path + ": " + why);
  }
}

void Recorder::open() {
  if (fd_ >= 0) return;
  int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw std::runtime_error("cannot open record file " + path_ + ": " + std::strerror(errno));
  fd_ = fd;
  if (!early_.empty() && !writeAll(fd_, early_.data(), early_.size())) {
    failed_ = true;
    log::error("record", "cannot write " + path_ + ": " + std::strerror(errno));
  }
  early_.clear();
  early_.shrink_to_fit();
  g_buffer.store(buffer_, std::memory_order_relaxed);
  g_used.store(used_, std::memory_order_relaxed);
  g_fd.store(fd_, std::memory_order_relaxed);
  catchCrashes();
}

Recorder::~Recorder() {
  flush();
  if (fd_ >= 0) {
    g_fd.store(-1, std::memory_order_relaxed);
    g_buffer.store(nullptr, std::memory_order_relaxed);
    ::close(fd_);
  }
  delete[] buffer_;
}

void Recorder::flush() {
  if (fd_ < 0) {  // not opened yet: the lines wait in memory (a start's few frames)
    early_.append(buffer_, used_);
    used_ = 0;
    lastFlush_ = std::chrono::steady_clock::now();
    return;
  }
  if (used_ > 0 && !failed_ && !writeAll(fd_, buffer_, used_)) {
    failed_ = true;  // said once; the run goes on without its record
    log::error("record", "cannot write " + path_ + ": " + std::strerror(errno));
  }
  used_ = 0;
  g_used.store(0, std::memory_order_relaxed);
  lastFlush_ = std::chrono::steady_clock::now();
}

void Recorder::write(double t, int car, bool tx, std::span<const std::uint8_t> frame,
                     const anki::Message& message, std::string_view extra) {
  char stamp[32];
  std::snprintf(stamp, sizeof stamp, "%.6f", t);
  std::string line;
  line.reserve(160);
  line.append("{\"t\":").append(stamp).append(",\"car\":").append(std::to_string(car));
  line.append(",\"dir\":\"").append(tx ? "tx" : "rx").append("\",\"hex\":\"");
  line.append(toHex(frame)).append("\",\"msg\":").append(anki::toJson(message).dump());
  line.append(extra).append("}\n");
  append(line);
}

bool Recorder::writeRace(double t, std::string_view race) {
  char stamp[32];
  std::snprintf(stamp, sizeof stamp, "%.6f", t);
  std::string line;
  line.reserve(race.size() + 32);
  line.append("{\"t\":").append(stamp).append(",\"race\":").append(race).append("}\n");
  if (line.size() - 1 > kMaxLineBytes) return false;
  append(line);
  return true;
}

void Recorder::writeLink(double t, int car, std::string_view link) {
  char head[64];
  std::snprintf(head, sizeof head, "{\"t\":%.6f,\"car\":%d,\"link\":", t, car);
  std::string line;
  line.reserve(link.size() + 64);
  line.append(head).append(link).append("}\n");
  if (line.size() - 1 <= kMaxLineBytes) append(line);
}

void Recorder::append(const std::string& line) {
  ++lines_;
  if (used_ + line.size() > kCapacity) flush();
  if (line.size() > kCapacity) {  // never: a frame is at most 20 bytes, a race line 64 KiB
    if (fd_ < 0)
      early_.append(line);
    else if (!failed_)
      writeAll(fd_, line.data(), line.size());
  } else {
    std::memcpy(buffer_ + used_, line.data(), line.size());
    used_ += line.size();
    g_used.store(used_, std::memory_order_relaxed);  // only whole lines are visible to a crash
  }
  if (std::chrono::steady_clock::now() - lastFlush_ >= kFlushEvery) flush();
}

}  // namespace pitwall
