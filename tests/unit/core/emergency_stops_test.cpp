#include "engine/core/emergency_stops.hpp"

#include <doctest/doctest.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <stdexcept>
#include <thread>
#include <vector>

using namespace pitwall;
using namespace std::chrono_literals;

namespace {
// A connected pair of sequenced-packet sockets, as BlueZ's AcquireWrite gives one end of.
struct Pair {
  int ours = -1, car = -1;
  Pair() {
    int fds[2];
    REQUIRE(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds) == 0);
    ours = fds[0];
    car = fds[1];
  }
  ~Pair() {
    ::close(ours);
    ::close(car);
  }
  // What the car got next, waiting at most `ms` (empty when nothing came).
  std::vector<std::uint8_t> received(int ms) const {
    struct pollfd p {
      car, POLLIN, 0
    };
    if (::poll(&p, 1, ms) != 1) return {};
    std::array<std::uint8_t, 64> buffer{};
    ssize_t n = ::recv(car, buffer.data(), buffer.size(), 0);
    if (n <= 0) return {};
    return {buffer.begin(), buffer.begin() + n};
  }
};
const std::vector<std::uint8_t> kStop{0x06, 0x24, 0x00, 0x00, 0xd4, 0x30, 0x00};

// One car registered, and a real loop watched with a limit of 300 ms.
struct Watched {
  Pair car;
  int slot = emergency::add(car.ours, kStop);
  Loop loop{ClockKind::Real};
  Watchdog watchdog{loop, std::chrono::milliseconds(300)};
  Watched() { REQUIRE(slot >= 0); }
  ~Watched() { emergency::remove(slot); }
};
}  // namespace

TEST_CASE("emergency stops: every registered socket gets its frame, a removed one nothing") {
  Pair a, b;
  int slotA = emergency::add(a.ours, kStop);
  int slotB = emergency::add(b.ours, std::vector<std::uint8_t>{0x01, 0x16});
  REQUIRE(slotA >= 0);
  REQUIRE(slotB >= 0);
  CHECK(emergency::count() == 2);
  CHECK(emergency::sendAll() == 2);
  CHECK(a.received(1000) == kStop);
  CHECK(b.received(1000) == std::vector<std::uint8_t>{0x01, 0x16});
  emergency::remove(slotB);
  CHECK(emergency::sendAll() == 1);
  CHECK(a.received(1000) == kStop);
  CHECK(b.received(0).empty());
  emergency::remove(slotA);
  CHECK(emergency::count() == 0);
  CHECK(emergency::sendAll() == 0);
  // nothing registered for a closed socket, an empty or oversized frame
  CHECK(emergency::add(-1, kStop) == -1);
  CHECK(emergency::add(a.ours, std::vector<std::uint8_t>{}) == -1);
  CHECK(emergency::add(a.ours, std::vector<std::uint8_t>(emergency::kFrameMax + 1, 0)) == -1);
}

// The adversary: a callback that never gives the loop back (it waits, inside the loop, for the
// very frame only the watchdog can send). The watchdog's thread sees the loop silent past its
// limit and sends the stop; the callback gets it, returns, and the loop turns again.
TEST_CASE("the watchdog stops the cars when the loop does not turn, once, and rearms") {
  Watched w;
  Pair& car = w.car;
  Loop& loop = w.loop;
  Watchdog& watchdog = w.watchdog;
  std::vector<std::uint8_t> got, later;
  loop.after(10ms, [&] {
    got = car.received(20000);  // the loop is wedged here until the stop comes
    later = car.received(500);  // still wedged: no second stop for the same stall
  });
  loop.after(50ms, [&] { loop.stop(); });
  loop.run();
  CHECK(got == kStop);
  CHECK(later.empty());
  CHECK(watchdog.fired() == 1);
}

TEST_CASE("the watchdog does not fire on a loop that turns, nor while held") {
  Watched w;
  Pair& car = w.car;
  Loop& loop = w.loop;
  Watchdog& watchdog = w.watchdog;
  // a second of a loop that turns, then a held stall (a suspended run)
  loop.after(1s, [&] {
    watchdog.hold(true);
    CHECK(car.received(600).empty());
    watchdog.hold(false);
    loop.stop();
  });
  loop.run();
  CHECK(watchdog.fired() == 0);
}

TEST_CASE("emergency stops: a busy slot (a frame half out on a byte stream) gets no stop") {
  Pair a;
  int slot = emergency::add(a.ours, kStop);
  REQUIRE(slot >= 0);
  emergency::setBusy(slot, true);
  CHECK(emergency::sendAll() == 0);
  CHECK(a.received(0).empty());
  emergency::setBusy(slot, false);
  CHECK(emergency::sendAll() == 1);
  CHECK(a.received(1000) == kStop);
  emergency::setBusy(slot, true);
  emergency::remove(slot);
  // a slot taken again starts free of the old one's busy mark
  slot = emergency::add(a.ours, kStop);
  CHECK(emergency::sendAll() == 1);
  CHECK(a.received(1000) == kStop);
  emergency::remove(slot);
}

TEST_CASE(
    "emergency stoppers: each runs once a call, a removed one never, a throwing one "
    "does not keep the others from theirs") {
  int ran = 0, other = 0;
  int id = emergency::addStopper([&] { return ++ran > 0; });
  int failing = emergency::addStopper([&]() -> bool { throw std::runtime_error("no bus"); });
  int unsent = emergency::addStopper([&] {
    ++other;
    return false;
  });
  CHECK(emergency::stopperCount() == 3);
  CHECK(emergency::runStoppers() == 1);
  CHECK(ran == 1);
  CHECK(other == 1);
  emergency::removeStopper(id);
  emergency::removeStopper(failing);
  CHECK(emergency::runStoppers() == 0);
  CHECK(ran == 1);
  CHECK(other == 2);
  emergency::removeStopper(unsent);
  emergency::removeStopper(0);  // ignored
  CHECK(emergency::stopperCount() == 0);
}

// The adversary again: the loop wedged in a callback; the stopper (a D-Bus call or an MQTT
// publish in the product) runs on the watchdog's thread, not on the wedged one.
TEST_CASE("the watchdog runs the stoppers when the loop does not turn") {
  Loop loop{ClockKind::Real};
  std::atomic<int> stops{0};
  std::atomic<bool> onLoopThread{false};
  const auto loopThread = std::this_thread::get_id();
  int id = emergency::addStopper([&] {
    onLoopThread = std::this_thread::get_id() == loopThread;
    ++stops;
    return true;
  });
  {
    Watchdog watchdog{loop, std::chrono::milliseconds(300)};
    loop.after(10ms, [&] {
      for (int i = 0; i < 2000 && stops == 0; ++i) std::this_thread::sleep_for(10ms);
    });
    loop.after(50ms, [&] { loop.stop(); });
    loop.run();
    CHECK(watchdog.fired() == 1);
  }
  emergency::removeStopper(id);
  CHECK(stops == 1);
  CHECK_FALSE(onLoopThread);
}

// The last-resort exit cannot make a D-Bus call from a signal handler: it asks the watchdog's
// thread, and waits for it a bounded time; without a watchdog or a stopper it does not wait.
TEST_CASE("askWatchdog: the stoppers run on the watchdog's thread while the asker waits") {
  std::atomic<int> stops{0};
  CHECK_FALSE(emergency::askWatchdog(2000ms));  // no watchdog, no stopper: at once
  int id = emergency::addStopper([&] { return ++stops > 0; });
  CHECK_FALSE(emergency::askWatchdog(2000ms));  // a stopper but no watchdog
  CHECK(stops == 0);
  {
    Loop loop{ClockKind::Real};
    Watchdog watchdog{loop, std::chrono::milliseconds(10000)};
    CHECK(emergency::askWatchdog(5000ms));  // the loop is not even running: the thread answers
    CHECK(stops == 1);
    CHECK(watchdog.fired() == 0);
  }
  emergency::removeStopper(id);
  CHECK_FALSE(emergency::askWatchdog(2000ms));
}
