#pragma once
// The one event loop of the engine: an asio::io_context plus a timer queue on an injected clock.
//
// Real clock: time is the steady clock since the loop was made; one asio::steady_timer is armed
// for the earliest timer. Virtual clock: time only moves when nothing is ready to run; then it
// jumps to the next due timer. Virtual runs are deterministic: timers due at the same instant
// fire in the order they were scheduled.
#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <unordered_map>

namespace pitwall {

using Duration = std::chrono::nanoseconds;
using TimePoint = std::chrono::nanoseconds;  // since the loop's epoch
enum class ClockKind { Real, Virtual };

inline double toSeconds(Duration d) {
  return std::chrono::duration<double>(d).count();
}
inline Duration fromSeconds(double s) {
  return std::chrono::duration_cast<Duration>(std::chrono::duration<double>(s));
}

class Loop {
 public:
  using TimerId = std::uint64_t;
  using Callback = std::function<void()>;

  explicit Loop(ClockKind kind);
  Loop(const Loop&) = delete;
  Loop& operator=(const Loop&) = delete;

  boost::asio::io_context& io() { return io_; }
  ClockKind clockKind() const { return kind_; }

  // Inline: every event reads it (virtual time is a field; real time reads the steady clock).
  TimePoint now() const { return kind_ == ClockKind::Virtual ? virtualNow_ : realNow(); }
  double seconds() const { return toSeconds(now()); }

  // Timers. A callback may schedule or cancel timers, including its own id (no effect).
  TimerId at(TimePoint when, Callback fn);
  TimerId after(Duration delay, Callback fn) { return at(now() + delay, std::move(fn)); }
  bool cancel(TimerId id);
  std::size_t pendingTimers() const { return timers_.size(); }
  std::optional<TimePoint> nextDue() const;

  // Runs fn soon on the loop, after what is already ready, without advancing time.
  void post(Callback fn);

  // A virtual run never sleeps: it calls `check` (if set) once per pass, before it polls. This is
  // how a signal handler's flag reaches a virtual run without an asynchronous read kept pending,
  // which would turn every poll into an epoll_wait (docs/performance.md, "--fast"). An empty
  // function removes it. Real runs never call it.
  void setPassCheck(Callback check) { passCheck_ = std::move(check); }

  // Runs until stop() is called, or until nothing is left that could ever run.
  void run();
  // Runs until stop() is called or `limit` of loop time has passed: false when the limit ended
  // it. (A stop() before the call is forgotten, as run() forgets it.)
  bool runAtMost(Duration limit);
  // Runs until done() holds, checked every millisecond of loop time (and not called again once
  // it held: it may consume what it checks), or `limit` has passed: false when the limit ended
  // it. Leaves no timer behind.
  bool runUntil(const std::function<bool()>& done, Duration limit);
  // stop() ends run() after the current callback; it can be called from any callback.
  void stop();
  bool stopped() const { return stopped_; }

 private:
  struct Key {
    TimePoint when;
    std::uint64_t seq;
    bool operator<(const Key& o) const { return when != o.when ? when < o.when : seq < o.seq; }
  };
  TimePoint realNow() const;
  bool fireDue();  // fires the timers due now; true when any fired
  void armRealTimer();
  void runVirtual();
  void runReal();

  ClockKind kind_;
  // Locking stays on (no BOOST_ASIO_CONCURRENCY_HINT_UNSAFE): asio's resolver completes from a
  // thread of its own, and with the hint the robots' TCP and UDP links broke.
  boost::asio::io_context io_;
  boost::asio::steady_timer wake_;
  std::chrono::steady_clock::time_point epoch_;
  TimePoint virtualNow_{0};
  std::map<Key, std::pair<TimerId, Callback>> timers_;
  std::unordered_map<TimerId, Key> keys_;
  std::uint64_t nextSeq_ = 0;
  TimerId nextId_ = 1;
  bool stopped_ = false;
  std::optional<TimePoint> armedFor_;
  Callback passCheck_;
};

}  // namespace pitwall
