#include "engine/core/emergency_stops.hpp"

#include <pthread.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <mutex>

#include "engine/core/log.hpp"

namespace pitwall {

namespace emergency {
namespace {

struct Slot {
  std::atomic<int> fd{-1};  // published after the frame (release), read before it (acquire)
  std::atomic<bool> taken{false};
  std::atomic<bool> busy{false};  // a frame partly written to its byte stream
  std::uint8_t frame[kFrameMax] = {};
  std::size_t size = 0;
};
std::array<Slot, kSlots> g_slots;
// sendAll()s under way (the watchdog's thread, a signal handler): remove() waits for them, so a
// socket is never closed — and its number given to another file — between a sender's read of
// it and its send(2).
std::atomic<int> g_sending{0};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free);

// The stoppers: run under the mutex, so removeStopper waits for a run under way.
std::mutex g_stopperMutex;
std::map<int, Stopper> g_stoppers;
int g_nextStopper = 0;
std::atomic<int> g_stopperCount{0};
// The last resort's requests (askWatchdog) and the watchdog's answers; watchdogs running.
std::atomic<int> g_asked{0}, g_answered{0}, g_watchdogs{0};

}  // namespace

int add(int fd, std::span<const std::uint8_t> stopFrame) {
  if (fd < 0 || stopFrame.empty() || stopFrame.size() > kFrameMax) return -1;
  for (std::size_t i = 0; i < kSlots; ++i) {
    Slot& slot = g_slots[i];
    bool expected = false;
    if (!slot.taken.compare_exchange_strong(expected, true)) continue;
    std::memcpy(slot.frame, stopFrame.data(), stopFrame.size());
    slot.size = stopFrame.size();
    slot.busy.store(false, std::memory_order_relaxed);
    slot.fd.store(fd, std::memory_order_release);
    return static_cast<int>(i);
  }
  log::warn("watchdog",
            "more than " + std::to_string(kSlots) + " cars: this one has no stop outside the loop");
  return -1;
}

void remove(int slot) {
  if (slot < 0 || slot >= static_cast<int>(kSlots)) return;
  g_slots[slot].fd.store(-1, std::memory_order_seq_cst);
  // A sender that read the socket before the store may still be sending to it: wait for it
  // (a few send(2) calls at most). On the thread a signal handler interrupts, the handler's
  // sendAll finishes before this goes on, so this never waits for itself.
  while (g_sending.load(std::memory_order_seq_cst) != 0) std::this_thread::yield();
  g_slots[slot].taken.store(false, std::memory_order_release);
}

void setBusy(int slot, bool busy) {
  if (slot < 0 || slot >= static_cast<int>(kSlots)) return;
  g_slots[slot].busy.store(busy, std::memory_order_seq_cst);
}

int sendAll() {
  int saved = errno;
  g_sending.fetch_add(1, std::memory_order_seq_cst);
  int sent = 0;
  for (Slot& slot : g_slots) {
    int fd = slot.fd.load(std::memory_order_seq_cst);
    if (fd < 0 || slot.busy.load(std::memory_order_seq_cst)) continue;
    if (::send(fd, slot.frame, slot.size, MSG_DONTWAIT | MSG_NOSIGNAL) ==
        static_cast<ssize_t>(slot.size))
      ++sent;
  }
  g_sending.fetch_sub(1, std::memory_order_seq_cst);
  errno = saved;
  return sent;
}

int count() {
  int n = 0;
  for (const Slot& slot : g_slots) n += slot.fd.load(std::memory_order_acquire) >= 0;
  return n;
}

int addStopper(Stopper stopper) {
  std::lock_guard lock(g_stopperMutex);
  int id = ++g_nextStopper;
  g_stoppers.emplace(id, std::move(stopper));
  g_stopperCount.store(static_cast<int>(g_stoppers.size()));
  return id;
}

void removeStopper(int id) {
  if (id == 0) return;
  std::lock_guard lock(g_stopperMutex);
  g_stoppers.erase(id);
  g_stopperCount.store(static_cast<int>(g_stoppers.size()));
}

int runStoppers() {
  std::lock_guard lock(g_stopperMutex);
  int sent = 0;
  for (auto& [id, stopper] : g_stoppers) {
    try {
      sent += stopper() ? 1 : 0;
    } catch (...) {  // a stopper's failure must not end the thread that stops the others
    }
  }
  return sent;
}

int stopperCount() {
  return g_stopperCount.load();
}

bool askWatchdog(std::chrono::milliseconds limit) {
  if (g_watchdogs.load() == 0 || g_stopperCount.load() == 0) return false;
  int ticket = g_asked.fetch_add(1) + 1;
  constexpr long kStepMs = 10;
  for (long waited = 0; waited < limit.count(); waited += kStepMs) {
    if (g_answered.load() >= ticket) return true;
    struct timespec step {
      0, kStepMs * 1000 * 1000
    };
    ::nanosleep(&step, nullptr);
  }
  return g_answered.load() >= ticket;
}

}  // namespace emergency

namespace {
constexpr auto kBeat = std::chrono::milliseconds(100);
}

std::int64_t Watchdog::nowMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

Watchdog::Watchdog(Loop& loop, std::chrono::milliseconds limit)
    : loop_(loop), limit_(limit), lastBeat_(nowMs()) {
  beat();
  emergency::g_watchdogs.fetch_add(1);
  // Signals are the loop thread's: the thread starts with every signal blocked (it inherits the
  // mask), so Ctrl-C's handler runs where the Lua code it interrupts runs.
  sigset_t all, old;
  sigfillset(&all);
  ::pthread_sigmask(SIG_SETMASK, &all, &old);
  thread_ = std::thread([this] { watch(); });
  ::pthread_sigmask(SIG_SETMASK, &old, nullptr);
}

Watchdog::~Watchdog() {
  quit_ = true;
  thread_.join();
  emergency::g_watchdogs.fetch_sub(1);
  loop_.cancel(timer_);
}

void Watchdog::hold(bool on) {
  if (!on) lastBeat_ = nowMs();
  held_ = on;
}

void Watchdog::beat() {
  lastBeat_ = nowMs();
  if (stuck_.exchange(false)) {
    double seconds = static_cast<double>(nowMs() - firedAt_.load()) / 1000 +
                     static_cast<double>(limit_.count()) / 1000;
    char text[160];
    std::snprintf(text, sizeof text,
                  "the loop was stuck for about %.1f s: the watchdog sent every car its stop; "
                  "the cars stay stopped until they are commanded again",
                  seconds);
    log::warn("watchdog", text);
  }
  timer_ = loop_.after(kBeat, [this] { beat(); });
}

void Watchdog::watch() {
  // A thread of its own; it only reads atomics, sends the registered stops, runs the stoppers
  // and writes to stderr.
  while (!quit_) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (int asked = emergency::g_asked.load(); asked > emergency::g_answered.load()) {
      emergency::runStoppers();  // the last-resort exit waits for this
      emergency::g_answered.store(asked);
    }
    if (held_ || stuck_) continue;
    std::int64_t silent = nowMs() - lastBeat_.load();
    if (silent < limit_.count()) continue;
    firedAt_ = nowMs();
    int sent = emergency::sendAll() + emergency::runStoppers();
    stuck_ = true;
    ++fired_;
    char text[200];
    int n = std::snprintf(text, sizeof text,
                          "\npitwall: the engine's loop has not turned for %.1f s: the watchdog "
                          "sent %d car%s its stop\n",
                          static_cast<double>(silent) / 1000, sent, sent == 1 ? "" : "s");
    if (n > 0) {
      ssize_t ignored = ::write(STDERR_FILENO, text, static_cast<std::size_t>(n));
      (void)ignored;
    }
  }
}

}  // namespace pitwall
