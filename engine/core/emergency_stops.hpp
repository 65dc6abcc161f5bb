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
#include <atomic>
#include <chrono>
#include <cstdint>
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
// Sends every registered stop once; how many went out. Async-signal-safe.
int sendAll();
// Registered slots (tests).
int count();

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
