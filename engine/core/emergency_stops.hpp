#pragma once
// The stop that does not need the loop (docs/safety.md "A stop that does not need the loop").
//
// A link that writes to a car through a socket of its own (BlueZ's AcquireWrite) registers that
// socket with the frame that stops the car, which the car's model gives it (the model knows what
// a stop is, the link when its socket opens and closes). Two things send every registered stop
// from outside the loop: the watchdog (a thread of its own) when the loop has not turned for a
// second, and the last-resort exit of the stop signals' handler. send() is async-signal-safe and
// thread-safe: a fixed table of slots, each an atomic socket and its frame, and send(2) with
// MSG_DONTWAIT | MSG_NOSIGNAL. A link takes its slot back before it closes the socket.
//
// A link whose stop needs more than one send(2) — a WriteValue call or an MQTT publish, each on
// a connection of its own, made there and then — registers a stopper instead: a function that
// only the watchdog's thread runs (it is not async-signal-safe). The last-resort exit asks that
// thread for them and waits for it, a bounded time, before it leaves.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <span>
#include <thread>

#include "engine/core/loop.hpp"

namespace pitwall {

namespace emergency {

inline constexpr std::size_t kSlots = 256;  // more cars than any race holds
inline constexpr std::size_t kFrameMax = 20;

// A slot for the socket `fd` and its stop frame, or -1 when every slot is taken (said in the
// log: that car then has no stop outside the loop).
int add(int fd, std::span<const std::uint8_t> stopFrame);
// The slot is free again; call before closing its socket. -1 is ignored.
void remove(int slot);
// A slot whose socket is a byte stream (TCP) is busy while a frame is partly written: no stop
// goes to it then, as a stop inside another frame would garble both. -1 is ignored.
void setBusy(int slot, bool busy);
// Sends every registered stop once; how many went out. Async-signal-safe.
int sendAll();
// Registered slots (tests).
int count();

// A stop sent from the watchdog's thread: true when it went out. It must bound its own time
// (a second at most) and own what it uses (no pointer to a link). An id; removeStopper waits
// for a run under way, so a link may destroy what the stopper reaches only after it.
using Stopper = std::function<bool()>;
int addStopper(Stopper stopper);
void removeStopper(int id);  // 0 is ignored
// Runs every stopper once; how many went out. Not async-signal-safe (the watchdog's thread).
int runStoppers();
// Stoppers registered (tests).
int stopperCount();

// The last-resort exit: asks a running watchdog to run the stoppers now and waits for it at
// most `limit`; false when no watchdog runs, there is no stopper, or the time ran out.
// Async-signal-safe.
bool askWatchdog(std::chrono::milliseconds limit);

}  // namespace emergency

// Watches one real-time loop from a thread: when the loop has not turned for `limit` (a timer of
// its own on the loop says it turned every 100 ms), every registered car gets its stop
// (emergency::sendAll) and stderr says so, once until the loop turns again; the loop then logs
// how long it was stuck. hold() while the process is meant to stand still (Ctrl-Z).
class Watchdog {
 public:
  Watchdog(Loop& loop, std::chrono::milliseconds limit);
  ~Watchdog();
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  void hold(bool on);
  // How many times it fired (tests).
  int fired() const { return fired_.load(); }

 private:
  static std::int64_t nowMs();
  void beat();
  void watch();

  Loop& loop_;
  std::chrono::milliseconds limit_;
  std::atomic<std::int64_t> lastBeat_;
  std::atomic<bool> held_{false}, quit_{false}, stuck_{false};
  std::atomic<int> fired_{0};
  std::atomic<std::int64_t> firedAt_{0};
  Loop::TimerId timer_ = 0;
  std::thread thread_;
};

}  // namespace pitwall
